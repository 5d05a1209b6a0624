// Wheel / track odometry of a mine robot: the base's forward speed and yaw rate as its drive encoders report
// them, with the errors that matter for dead reckoning (a crawler on a wet, rough floor):
//
//   speed    = v_forward(t) * (1 + slip(t)) + n_v,      slip in [3 %, 8 %]: tracks turn faster than the ground
//   yaw_rate = omega_z(t) * (1 + yaw_scale) + n_w       skid steering: the effective track width is not the
//                                                       nominal one (yaw_scale within +-yaw_scale_max)
// slip(t) = slip_mean + slip_swing * sin(2 pi t / slip_period + phase): a per-run mean drawn uniformly so that
// mean +- swing stays within [slip_min, slip_max], varying slowly (floor changes over minutes). v_forward is
// the velocity of the base (the ground contact below the lidar, mount_height lower on the body z axis) along
// the body x axis, so the mast's sway (chassis vibration) is not in it, as it is not in a real encoder.
// Everything is drawn from the run's seed on its own random stream (rng.hpp): the same config gives the same
// readings, and enabling the wheel stream changes no other stream's noise.
#pragma once

#include "core/config.hpp"
#include "core/types.hpp"
#include "core/wheel_odom.hpp"
#include "sim/bspline_trajectory.hpp"
#include "sim/rng.hpp"

namespace adit::sim {

struct WheelOdomConfig {
  bool enabled = false;        // publish WHEEL_ODOM (a robot with wheel / track odometry)
  double rate_hz = 50.0;       // readings per second
  double slip_min = 0.03;      // range the slip stays in (fraction of the true speed)
  double slip_max = 0.08;
  double slip_swing = 0.01;    // amplitude of the slow variation around the run's mean
  double slip_period_s = 300.0;
  double yaw_scale_max = 0.03; // largest relative error of the yaw rate (effective track width)
  double speed_noise = 0.02;   // m/s 1-sigma white noise per reading
  double yaw_rate_noise = 0.01;  // rad/s
  bool noiseless = false;      // exact readings, no slip (tests)
};

// Keys "sim.wheel.<field>" with the defaults above.
WheelOdomConfig wheelOdomConfigFrom(const adit::Config& c);

class WheelOdomSimulator {
 public:
  WheelOdomSimulator(const WheelOdomConfig& config, double mount_height, std::uint64_t seed);
  // The reading at time t (s); requested in time order, once each (noise is drawn per call).
  WheelOdomSample sample(const BSplineTrajectory& trajectory, double t, std::int64_t utime);
  // The slip at time t (fraction), for tests.
  double slip(double t) const;
  const WheelOdomConfig& config() const { return config_; }

 private:
  WheelOdomConfig config_;
  double mount_height_;
  Rng rng_;
  double slip_mean_ = 0.0, slip_phase_ = 0.0, yaw_scale_ = 0.0;
};

}  // namespace adit::sim
