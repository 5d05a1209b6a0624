// The gyro's bias, measured whenever the robot stands still. A MEMS gyro (N100 class) turns on with a bias
// of ~0.2 deg/s that drifts with temperature; integrated over a sweep it is a rotation the lidar does not
// make, so a gyro that seeds or weighs the registration must have it removed. At rest the true rate is zero
// (an idling chassis shakes about zero), so the mean reading over a still period is the bias.
//
// A sweep interval is still when the lidar odometry's step is short (rest_translation_m) and the gyro turned
// less than rest_rotation_deg over it.
// A still period ends at a moving step, or when the mean acceleration over its last window_s leaves the
// mean of the period before it by accel_tolerance_mps2: a vehicle pulling away slowly accelerates before the
// lidar sees it move, while an idling chassis' vibration (1-4 Hz) averages out over the window. A period's
// bias is the slope of a straight line fitted to the gyro's integrated angle over the period without its
// newest guard_s (not trusted until more follows), once that spans min_rest_s: the chassis rocks about a
// fixed attitude, so the fit through every sample errs far less than the mean rate, whose error is the net
// rotation between the period's two ends over its length. Each period weighs (per axis) by the inverse of its
// slope's variance, from the fit's residual (the rocking) and the gyro's noise, and is blended with the
// estimate before it, older periods fading with time_constant_s, and with a prior of zero (the turn-on
// bias, initial_sigma_rad_s). Deterministic: depends only on the samples and steps given, in order.
#pragma once

#include "core/config_table.hpp"
#include "core/types.hpp"

#include <deque>
#include <vector>

namespace adit {

struct GyroBiasConfig {
  // A lidar step shorter than this, with the gyro turning less than the angle, may be still. Generous:
  // scan-to-scan odometry at rest moves ~1-3 cm a sweep on a noisy 16-beam lidar; a mine robot under way
  // makes >= 5 cm (0.5 m/s). An idling chassis rocks by up to ~0.4 deg a sweep.
  double rest_translation_m = 0.05;
  double rest_rotation_deg = 1.0;
  double accel_tolerance_mps2 = 0.1;  // the recent window's mean acceleration against the period's before it
  double window_s = 1.0;
  double min_rest_s = 1.0;         // still this long (after the guard) before the mean counts as the bias
  double guard_s = 0.5;            // the newest part of a still period, not trusted until more follows
  double time_constant_s = 600.0;  // older periods fade with this time constant (the bias drifts with temperature)
  // A larger mean rate while still is not a bias but a slow turn misread as still (N100-class turn-on bias:
  // ~0.2 deg/s, 1 sigma).
  double max_bias_rad_s = 0.02;
  // The bias's standard deviation before a stop has measured it (per axis): the gyro is still far better
  // than a noisy 16-beam lidar's rotation over one sweep, with its rotation's sigma widened by this times
  // the interval.
  double initial_sigma_rad_s = 0.005;
  // A period's slope variance: 12 r^2 rocking_correlation_s / L^3 + noise_density^2 / L, where r^2 is the
  // fit's mean squared residual (the rocking about the line) and L the period's length. The rocking is
  // correlated over a fraction of its period, not from sample to sample; the noise is the gyro's white
  // noise density (N100 class: 1.7e-4 rad/s/sqrt(Hz)). Measured at rest on the simulator (idle_vibration
  // 0.5, noisy sensors): the mean rate of the first still seconds taken as the bias, as before this fit,
  // turned scan-to-scan odometry's roll 2.3 deg in 30 s (periods end every few seconds there).
  double rocking_correlation_s = 0.25;
  double noise_density_rad_s_sqrt_hz = 1.7e-4;
};

// Keys "odometry.gyro_bias.*".
const ConfigTable<GyroBiasConfig>& gyroBiasConfigTable();

class GyroBiasEstimator {
 public:
  explicit GyroBiasEstimator(const GyroBiasConfig& config = {}) : config_(config) {}

  // One sweep interval (t0, t1] (utime), the IMU samples around it (IMU frame; those outside are ignored) and
  // the lidar odometry's step over it (its translation counts; step_valid false: a failed or missing
  // registration, which ends a still period like a moving step).
  void observe(const std::vector<ImuSample>& imu, std::int64_t t0, std::int64_t t1, const Eigen::Isometry3d& step,
               bool step_valid);

  bool known() const { return periods_ > 0; }
  // rad/s, IMU frame (zero until known): the still periods' slopes, drawn towards zero (the turn-on bias's
  // prior) by how little they are worth.
  Eigen::Vector3d bias() const;
  int restPeriods() const { return periods_; }           // still periods blended in so far
  // The bias's standard deviation (rad/s, the largest over the axes): initial_sigma_rad_s until a stop
  // measured it, then the periods' and the prior's combined.
  double biasSigma() const;
  // The sigma of a gyro rotation over interval_s: sigma_rad widened by the bias's sigma times the interval.
  double rotationSigma(double sigma_rad, double interval_s) const;

 private:
  // Sums over an interval's samples; t (s) and the integrated angle theta (rad) count from the period's start.
  struct Interval {
    std::int64_t t0 = 0, t1 = 0;
    Eigen::Vector3d rate_sum = Eigen::Vector3d::Zero();  // this interval only: how far the gyro turned
    Eigen::Vector3d accel_sum = Eigen::Vector3d::Zero();
    double samples = 0.0;
    double t_sum = 0.0, t_sq_sum = 0.0;
    Eigen::Array3d theta_sum = Eigen::Array3d::Zero(), theta_sq_sum = Eigen::Array3d::Zero(),
                   theta_t_sum = Eigen::Array3d::Zero();
    void add(const Interval& o);
  };
  // Line fitted to theta(t): slope and the slope's variance per axis.
  struct Slope {
    Eigen::Array3d rate = Eigen::Array3d::Zero(), variance = Eigen::Array3d::Zero();
  };
  Slope fit(const Interval& sums, double length_s) const;
  void integrate(const std::vector<ImuSample>& imu, Interval& s);
  bool accelerating() const;
  void endPeriod();
  void update();
  void settle();

  GyroBiasConfig config_;
  double priorWeight() const;
  // The still periods' blended slopes and their weights (inverse variances, faded), per axis.
  Eigen::Array3d mean_ = Eigen::Array3d::Zero();
  Eigen::Array3d weight_ = Eigen::Array3d::Zero();
  // The estimate before the still period in progress (faded to its start).
  Eigen::Array3d base_ = Eigen::Array3d::Zero();
  Eigen::Array3d base_weight_ = Eigen::Array3d::Zero();
  std::int64_t base_utime_ = 0;
  // The still period in progress: when it began, the sums of its settled intervals (settle()), and the rest.
  std::int64_t period_start_ = 0;
  Eigen::Array3d theta_ = Eigen::Array3d::Zero();  // the gyro integrated since the period's start (rad)
  std::int64_t last_sample_utime_ = 0;
  Interval settled_;
  std::deque<Interval> period_;
  bool counted_ = false;   // the period in progress has entered the estimate
  int periods_ = 0;
};

// The samples with `bias` removed from their rates.
std::vector<ImuSample> withoutGyroBias(std::vector<ImuSample> imu, const Eigen::Vector3d& bias);

}  // namespace adit
