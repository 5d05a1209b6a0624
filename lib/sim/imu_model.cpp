#include "sim/imu_model.hpp"

#include <cmath>

namespace adit::sim {

ImuConfig imuConfigFrom(const adit::Config& cfg) {
  ImuConfig c;
  const std::string p = "sim.imu.";
  c.rate_hz = cfg.get(p + "rate_hz", c.rate_hz);
  c.gyro_noise = cfg.get(p + "gyro_noise", c.gyro_noise);
  c.gyro_bias_walk = cfg.get(p + "gyro_bias_walk", c.gyro_bias_walk);
  c.gyro_bias_init = cfg.get(p + "gyro_bias_init", c.gyro_bias_init);
  c.accel_noise = cfg.get(p + "accel_noise", c.accel_noise);
  c.accel_bias_walk = cfg.get(p + "accel_bias_walk", c.accel_bias_walk);
  c.accel_bias_init = cfg.get(p + "accel_bias_init", c.accel_bias_init);
  c.gravity = cfg.get(p + "gravity", c.gravity);
  c.noiseless = cfg.get(p + "noiseless", c.noiseless);
  return c;
}

ImuSimulator::ImuSimulator(const ImuConfig& config, std::uint64_t seed)
    : config_(config), rng_(Rng::forStream(seed, Stream::Imu)) {
  for (int k = 0; k < 3; ++k) gyro_bias_[k] = rng_.normal(0.0, config_.gyro_bias_init);
  for (int k = 0; k < 3; ++k) accel_bias_[k] = rng_.normal(0.0, config_.accel_bias_init);
  if (config_.noiseless) {
    gyro_bias_.setZero();
    accel_bias_.setZero();
  }
}

ImuSample ImuSimulator::sample(const BSplineTrajectory& trajectory, double t, std::int64_t utime, ImuTruth* truth) {
  const TrajectoryState s = trajectory.state(t);
  const Eigen::Vector3d gravity(0.0, 0.0, -config_.gravity);
  const Eigen::Matrix3d R = s.pose.linear();
  ImuSample out;
  out.utime = utime;
  out.gyro = s.angular_velocity + gyro_bias_;
  out.accel = R.transpose() * (s.acceleration - gravity) + accel_bias_;
  // Fixed draws per sample (12 normals) whether or not noise is on, so streams stay aligned.
  const double root_rate = std::sqrt(config_.rate_hz), root_dt = 1.0 / root_rate;
  Eigen::Vector3d ng, na, wg, wa;
  for (int k = 0; k < 3; ++k) ng[k] = rng_.normal();
  for (int k = 0; k < 3; ++k) na[k] = rng_.normal();
  for (int k = 0; k < 3; ++k) wg[k] = rng_.normal();
  for (int k = 0; k < 3; ++k) wa[k] = rng_.normal();
  if (truth) {
    truth->gyro_bias = gyro_bias_;
    truth->accel_bias = accel_bias_;
    truth->state = s;
  }
  if (!config_.noiseless) {
    out.gyro += config_.gyro_noise * root_rate * ng;
    out.accel += config_.accel_noise * root_rate * na;
    gyro_bias_ += config_.gyro_bias_walk * root_dt * wg;
    accel_bias_ += config_.accel_bias_walk * root_dt * wa;
  }
  return out;
}

}  // namespace adit::sim
