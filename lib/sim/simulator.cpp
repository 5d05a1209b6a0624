#include "sim/simulator.hpp"

#include <cmath>
#include <stdexcept>
#include <string>

namespace adit::sim {
namespace {

WorldConfig resolveWorld(const SimConfig& c) {
  if (!c.roadway) return worldConfigFor(c.world, c.seed);
  // simConfigFrom resolves the geometry from sim.world and sim.seed; a world or seed changed on the struct
  // afterwards would silently simulate the geometry of the old one. Set them in the configuration instead.
  if (c.roadway->name != c.world || c.roadway->seed != c.seed)
    throw std::invalid_argument("sim: world '" + c.world + "' seed " + std::to_string(c.seed) +
                                " does not match the resolved geometry of '" + c.roadway->name + "' seed " +
                                std::to_string(c.roadway->seed) +
                                " (set sim.world / sim.seed before simConfigFrom, or reset SimConfig::roadway)");
  return *c.roadway;
}

}  // namespace

SimConfig simConfigFrom(const adit::Config& cfg) {
  SimConfig c;
  c.world = cfg.get<std::string>("sim.world", c.world);
  c.sensor = cfg.get<std::string>("sim.sensor", c.sensor);
  c.duration_s = cfg.get("sim.duration", c.duration_s);
  c.seed = cfg.get("sim.seed", c.seed);
  c.start_utime = cfg.get("sim.start_utime", c.start_utime);
  c.roadway = worldConfigFrom(cfg, c.world, c.seed);
  c.motion = motionConfigFrom(cfg);
  c.lidar = lidarNoiseConfigFrom(cfg);
  c.lidar.dust = cfg.get("sim.dust", c.lidar.dust);
  c.imu = imuConfigFrom(cfg);
  c.wheel = wheelOdomConfigFrom(cfg);
  return c;
}

SimConfig simConfigFrom(adit::Config cfg, const std::string& world, std::uint64_t seed) {
  cfg.set("sim.world", world);
  cfg.set("sim.seed", std::to_string(seed));
  return simConfigFrom(cfg);
}

Simulator::Simulator(const SimConfig& config)
    : config_(config),
      world_(std::make_unique<World>(buildWorld(resolveWorld(config)))),
      motion_(planMotion(*world_, config.motion, config.duration_s, config.seed)),
      lidar_(lidarProfile(config.sensor), config.lidar),
      caster_(world_->scene),
      imu_(config.imu, config.seed),
      wheel_(config.wheel, config.motion.mount_height, config.seed) {
  if (!(config.duration_s >= 0.0) || !(config.imu.rate_hz > 0.0))
    throw std::invalid_argument("sim: duration must be >= 0 and imu rate > 0");
  sweep_period_us_ = std::llround(1e6 * lidar_.profile().sweepDuration());
  num_sweeps_ = static_cast<std::int64_t>(std::floor(config.duration_s * 1e6 / sweep_period_us_ + 1e-9));
  num_imu_ = static_cast<std::int64_t>(std::floor(config.duration_s * config.imu.rate_hz + 1e-9)) + 1;
  if (config.wheel.enabled) {
    if (!(config.wheel.rate_hz > 0.0)) throw std::invalid_argument("sim: wheel odometry rate must be > 0");
    num_wheel_ = static_cast<std::int64_t>(std::floor(config.duration_s * config.wheel.rate_hz + 1e-9)) + 1;
  }
}

std::int64_t Simulator::sweepUtime(std::int64_t seq) const { return config_.start_utime + (seq + 1) * sweep_period_us_; }

LidarScan Simulator::simulateSweep(std::int64_t seq, bool frozen) const {
  const std::int64_t utime = sweepUtime(seq);
  const double t_end = secondsOf(utime);
  const BSplineTrajectory& traj = motion_.trajectory;
  if (frozen || config_.freeze_sweep_motion) {
    const Eigen::Isometry3d fixed = traj.pose(t_end);
    return lidar_.simulate(caster_, [&](double) { return fixed; }, t_end, utime, seq, config_.seed);
  }
  return lidar_.simulate(caster_, [&](double t) { return traj.pose(t); }, t_end, utime, seq, config_.seed);
}

StampedPose Simulator::groundTruth(std::int64_t utime) const {
  return {utime, motion_.trajectory.pose(secondsOf(utime))};
}

std::int64_t Simulator::wheelUtime(std::int64_t index) const {
  return config_.start_utime + std::llround(static_cast<double>(index) * 1e6 / config_.wheel.rate_hz);
}

bool Simulator::next(SimEvent& event) {
  const bool have_imu = next_imu_ < num_imu_, have_sweep = next_sweep_ < num_sweeps_;
  const bool have_wheel = next_wheel_ < num_wheel_;
  if (!have_imu && !have_sweep && !have_wheel) return false;
  const std::int64_t imu_utime =
      config_.start_utime + std::llround(static_cast<double>(next_imu_) * 1e6 / config_.imu.rate_hz);
  const std::int64_t sweep_utime = sweepUtime(next_sweep_);
  // At equal stamps: IMU, then wheel, then the sweep (what covers a sweep has arrived before it).
  if (have_wheel && (!have_imu || wheelUtime(next_wheel_) < imu_utime) &&
      (!have_sweep || wheelUtime(next_wheel_) <= sweep_utime)) {
    const std::int64_t utime = wheelUtime(next_wheel_);
    event.kind = SimEvent::Kind::Wheel;
    event.wheel = wheel_.sample(motion_.trajectory, static_cast<double>(next_wheel_) / config_.wheel.rate_hz, utime);
    event.truth = groundTruth(utime);
    event.scan = LidarScan{};
    ++next_wheel_;
    return true;
  }
  if (have_imu && (!have_sweep || imu_utime <= sweep_utime)) {
    const double t = static_cast<double>(next_imu_) / config_.imu.rate_hz;
    event.kind = SimEvent::Kind::Imu;
    event.imu = imu_.sample(motion_.trajectory, t, imu_utime, &event.imu_truth);
    event.truth = {imu_utime, event.imu_truth.state.pose};
    event.scan = LidarScan{};
    ++next_imu_;
    return true;
  }
  event.kind = SimEvent::Kind::Scan;
  event.scan = simulateSweep(next_sweep_);
  event.truth = groundTruth(sweep_utime);
  ++next_sweep_;
  return true;
}

std::vector<Eigen::Vector3f> Simulator::worldPointCloud(double spacing) const {
  return sampleSurfaces(world_->scene, spacing, config_.seed);
}

}  // namespace adit::sim
