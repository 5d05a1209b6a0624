// adit::sim::Simulator: a robot driving through a synthetic underground roadway, as a pull stream of time-ordered
// lidar sweeps and IMU samples with exact ground truth. The `adit sim` CLI writes these to an LCM log.
//
// Ground truth: T_world_lidar at each sweep's utime, i.e. the instant of the sweep's LAST firing (the same
// convention as LidarScan.utime). World frame: z up, the robot starts near the origin heading +x (loop, straight)
// standing still for motion.start_still seconds.
// Extrinsic: the IMU frame is the lidar frame (identity T_lidar_imu), so IMU readings are the lidar's own
// angular velocity and specific force.
// Clock: time 0 is start_utime; sweep k (seq k) ends at start_utime + (k + 1) * 100000 us (10 Hz), IMU sample i is
// at start_utime + round(i * 1e6 / rate) us. Events come out in utime order, an IMU sample before a sweep with
// the same utime (so the IMU covering a sweep has arrived before it).
// Determinism: everything is a pure function of SimConfig; each sweep's noise has its own random stream, so
// simulateSweep(k) alone gives the same scan as the k-th sweep of the stream.
//
// Demo duration: roadway-loop's circuit is 510 m (507 m as driven, corners rounded); at the default cruise speed
// 1.3 m/s the robot completes one lap about 405 s after time 0 and 1.2 laps (608 m) at about 483 s (it stands
// still for the first 2 s). Use --duration 500 for the demo: a loop closure with a real revisit. The exact
// figures for a config are timeAtDistance(lapLength()) and timeAtDistance(1.2 * lapLength()); test_sim prints
// and checks them.
#pragma once

#include "core/config.hpp"
#include "core/types.hpp"
#include "sim/imu_model.hpp"
#include "sim/lidar_model.hpp"
#include "sim/motion.hpp"
#include "sim/wheel_model.hpp"
#include "sim/world.hpp"

#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <vector>

namespace adit::sim {

struct SimConfig {
  std::string world = "roadway-loop";  // roadway-straight | roadway-loop | room-and-pillar | featureless
  std::string sensor = "vlp16";        // vlp16 | rs16 | hdl64
  double duration_s = 60.0;            // simulated seconds (sweeps and IMU samples up to this time)
  std::uint64_t seed = 1;              // drives the world, the motion, and all noise
  std::int64_t start_utime = 1700000000000000;  // utime of time 0 (2023-11-14), any value works
  // World geometry; unset = worldConfigFor(world, seed). When set, its name and seed must equal world and seed
  // (the Simulator throws otherwise): change sim.world / sim.seed in the configuration, not on this struct.
  std::optional<WorldConfig> roadway;
  MotionConfig motion;
  LidarNoiseConfig lidar;
  ImuConfig imu;
  WheelOdomConfig wheel;  // wheel / track odometry (off by default: not every robot has it)
  // Test hook: every firing of a sweep uses the pose at the sweep's utime (no motion distortion).
  bool freeze_sweep_motion = false;
};

// Keys: sim.world, sim.sensor, sim.duration, sim.seed, sim.start_utime, sim.dust (shortcut for sim.lidar.dust),
// sim.roadway.* (WorldConfig fields), sim.motion.* (MotionConfig), sim.lidar.* (LidarNoiseConfig),
// sim.imu.* (ImuConfig), sim.wheel.* (WheelOdomConfig); every default as documented on the structs (launch/worlds/roadway-loop.yaml lists them
// all). Throws std::invalid_argument for an unknown world, std::runtime_error for a value that does not parse.
SimConfig simConfigFrom(const adit::Config& c);
// The same with sim.world and sim.seed replaced before the world's geometry is resolved.
SimConfig simConfigFrom(adit::Config c, const std::string& world, std::uint64_t seed);

struct SimEvent {
  enum class Kind { Scan, Imu, Wheel };
  Kind kind = Kind::Imu;
  LidarScan scan;      // Kind::Scan
  ImuSample imu;       // Kind::Imu
  StampedPose truth;   // T_world_lidar at scan.utime (Scan) or at the sample time (Imu)
  ImuTruth imu_truth;  // Kind::Imu: biases and exact state
  WheelOdomSample wheel;  // Kind::Wheel (only with config.wheel.enabled)
};

class Simulator {
 public:
  // Builds the world and plans the motion; throws std::invalid_argument for unknown names or bad sizes.
  explicit Simulator(const SimConfig& config);

  // Next event in utime order; false once both streams are past duration_s.
  bool next(SimEvent& event);

  // Random access to sweep `seq` (0-based), identical to the stream's; `frozen` = no motion within the sweep.
  // Not thread-safe (it updates the ray caster's crop of the world).
  LidarScan simulateSweep(std::int64_t seq, bool frozen = false) const;
  std::int64_t sweepUtime(std::int64_t seq) const;
  std::int64_t numSweeps() const { return num_sweeps_; }
  std::int64_t numImuSamples() const { return num_imu_; }

  // T_world_lidar at any utime (the ground-truth file uses the sweeps' utimes).
  StampedPose groundTruth(std::int64_t utime) const;
  double secondsOf(std::int64_t utime) const { return static_cast<double>(utime - config_.start_utime) * 1e-6; }

  const SimConfig& config() const { return config_; }
  const World& world() const { return *world_; }
  const BSplineTrajectory& trajectory() const { return motion_.trajectory; }
  const PlannedMotion& motion() const { return motion_; }
  const LidarSimulator& lidar() const { return lidar_; }

  // Length of one lap of a closed route as driven (corners rounded) (m), or of the whole route if open.
  double lapLength() const { return motion_.lap_length; }
  // Seconds after time 0 at which the robot has driven `metres`; +inf if not within the planned horizon.
  double timeAtDistance(double metres) const { return motion_.timeAtDistance(metres); }

  // Points sampled on every surface of the world, ~one per spacing^2 (m^2), deterministic: for "world as PCD".
  std::vector<Eigen::Vector3f> worldPointCloud(double spacing) const;

 private:
  SimConfig config_;
  std::unique_ptr<World> world_;
  PlannedMotion motion_;
  LidarSimulator lidar_;
  mutable LocalRayCaster caster_;  // crop of the world around the sensor; a cache, results do not depend on it
  ImuSimulator imu_;
  WheelOdomSimulator wheel_;
  std::int64_t sweep_period_us_ = 100000;
  std::int64_t num_sweeps_ = 0, num_imu_ = 0;
  std::int64_t next_sweep_ = 0, next_imu_ = 0;
  std::int64_t num_wheel_ = 0, next_wheel_ = 0;
  std::int64_t wheelUtime(std::int64_t index) const;
};

// Points on the surfaces of a scene, about one per spacing^2 of area, from a fixed random stream.
std::vector<Eigen::Vector3f> sampleSurfaces(const Scene& scene, double spacing, std::uint64_t seed);

}  // namespace adit::sim
