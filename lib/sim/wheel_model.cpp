#include "sim/wheel_model.hpp"

#include <algorithm>
#include <cmath>

namespace adit::sim {

WheelOdomConfig wheelOdomConfigFrom(const adit::Config& cfg) {
  WheelOdomConfig c;
  const std::string p = "sim.wheel.";
  c.enabled = cfg.get(p + "enabled", c.enabled);
  c.rate_hz = cfg.get(p + "rate_hz", c.rate_hz);
  c.slip_min = cfg.get(p + "slip_min", c.slip_min);
  c.slip_max = cfg.get(p + "slip_max", c.slip_max);
  c.slip_swing = cfg.get(p + "slip_swing", c.slip_swing);
  c.slip_period_s = cfg.get(p + "slip_period_s", c.slip_period_s);
  c.yaw_scale_max = cfg.get(p + "yaw_scale_max", c.yaw_scale_max);
  c.speed_noise = cfg.get(p + "speed_noise", c.speed_noise);
  c.yaw_rate_noise = cfg.get(p + "yaw_rate_noise", c.yaw_rate_noise);
  c.noiseless = cfg.get(p + "noiseless", c.noiseless);
  return c;
}

WheelOdomSimulator::WheelOdomSimulator(const WheelOdomConfig& config, double mount_height, std::uint64_t seed)
    : config_(config), mount_height_(mount_height), rng_(Rng::forStream(seed, Stream::Wheel)) {
  // The mean is drawn so that mean +- swing stays inside [slip_min, slip_max].
  const double swing = std::max(0.0, std::min(config_.slip_swing, 0.5 * (config_.slip_max - config_.slip_min)));
  config_.slip_swing = swing;
  slip_mean_ = rng_.uniform(config_.slip_min + swing, config_.slip_max - swing);
  slip_phase_ = rng_.uniform(0.0, 6.283185307179586);
  yaw_scale_ = rng_.uniform(-config_.yaw_scale_max, config_.yaw_scale_max);
}

double WheelOdomSimulator::slip(double t) const {
  if (config_.noiseless) return 0.0;
  const double period = std::max(1e-3, config_.slip_period_s);
  return slip_mean_ + config_.slip_swing * std::sin(6.283185307179586 * t / period + slip_phase_);
}

WheelOdomSample WheelOdomSimulator::sample(const BSplineTrajectory& trajectory, double t, std::int64_t utime) {
  const TrajectoryState s = trajectory.state(t);
  // The base is mount_height below the lidar on the body z axis: v_base = v_lidar - omega x (R e_z h).
  const Eigen::Matrix3d R = s.pose.linear();
  const Eigen::Vector3d v_body =
      R.transpose() * s.velocity - s.angular_velocity.cross(Eigen::Vector3d(0.0, 0.0, mount_height_));
  const double n_v = rng_.normal(), n_w = rng_.normal();  // fixed draws per reading: streams stay aligned
  WheelOdomSample out;
  out.utime = utime;
  out.speed = v_body.x() * (1.0 + slip(t));
  out.yaw_rate = s.angular_velocity.z();
  // Encoders read exactly zero when the tracks stand still.
  if (!config_.noiseless && std::abs(v_body.x()) > 1e-3) {
    out.yaw_rate *= 1.0 + yaw_scale_;
    out.speed += config_.speed_noise * n_v;
    out.yaw_rate += config_.yaw_rate_noise * n_w;
  }
  return out;
}

}  // namespace adit::sim
