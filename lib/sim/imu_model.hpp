// IMU model of a WHEELTEC N100-class MEMS unit (100-200 Hz): gyro and accelerometer with white noise and bias
// random walk, measuring the ground-truth trajectory's exact angular velocity and specific force.
//
//   gyro  = omega_body(t) + b_g + n_g,        n_g ~ N(0, gyro_noise^2 * rate)      (per sample)
//   accel = R(t)^T (a_world(t) - g) + b_a + n_a, g = (0, 0, -gravity)             (+gravity up at rest)
//   b_g, b_a: start ~N(0, *_bias_init^2) per axis, random walk b += N(0, *_bias_walk^2 / rate) per sample.
// The IMU frame is the lidar frame (identity extrinsic, documented in simulator.hpp). The optional orientation
// and magnetic_field of ImuSample are left empty: the N100's on-board AHRS output is not modelled.
#pragma once

#include "core/config.hpp"
#include "core/types.hpp"
#include "sim/bspline_trajectory.hpp"
#include "sim/rng.hpp"

namespace adit::sim {

struct ImuConfig {
  double rate_hz = 200.0;            // samples per second (N100: 100-200 Hz)
  double gyro_noise = 1.7e-4;        // rad/s/sqrt(Hz) white noise density (~0.01 deg/s/sqrt(Hz))
  double gyro_bias_walk = 2.0e-5;    // rad/s^2/sqrt(Hz) bias random walk
  double gyro_bias_init = 0.003;     // rad/s 1-sigma turn-on bias (~0.17 deg/s)
  double accel_noise = 1.5e-3;       // m/s^2/sqrt(Hz) (~150 ug/sqrt(Hz))
  double accel_bias_walk = 2.0e-4;   // m/s^3/sqrt(Hz)
  double accel_bias_init = 0.03;     // m/s^2 1-sigma turn-on bias (~3 mg)
  double gravity = 9.80665;          // m/s^2
  bool noiseless = false;            // exact readings, zero biases (tests)
};

// Keys "sim.imu.<field>" with the defaults above.
ImuConfig imuConfigFrom(const adit::Config& c);

struct ImuTruth {
  Eigen::Vector3d gyro_bias = Eigen::Vector3d::Zero();   // bias contained in this sample (rad/s)
  Eigen::Vector3d accel_bias = Eigen::Vector3d::Zero();  // (m/s^2)
  TrajectoryState state;                                  // exact state at the sample time
};

class ImuSimulator {
 public:
  ImuSimulator(const ImuConfig& config, std::uint64_t seed);
  // Next sample at time t (s); samples must be requested in time order, once each (biases walk per call).
  ImuSample sample(const BSplineTrajectory& trajectory, double t, std::int64_t utime, ImuTruth* truth = nullptr);
  const ImuConfig& config() const { return config_; }

 private:
  ImuConfig config_;
  Rng rng_;
  Eigen::Vector3d gyro_bias_, accel_bias_;
};

}  // namespace adit::sim
