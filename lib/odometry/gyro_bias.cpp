#include "odometry/gyro_bias.hpp"

#include "core/geometry.hpp"

#include <cmath>

namespace adit {

const ConfigTable<GyroBiasConfig>& gyroBiasConfigTable() {
  using G = GyroBiasConfig;
  static const ConfigTable<G> table = [] {
    ConfigTable<G> t("odometry.gyro_bias");
    t.add("rest_translation_m", &G::rest_translation_m, above(0), "m", "a lidar step shorter than this (and the gyro turned less than the angle) may be still")
     .add("rest_rotation_deg", &G::rest_rotation_deg, above(0), "deg", "a sweep interval the gyro turns less than this (and the lidar step is short) may be still")
     .add("accel_tolerance_mps2", &G::accel_tolerance_mps2, above(0), "m/s^2", "the last window's mean acceleration this far from the still period's before it ends the period")
     .add("window_s", &G::window_s, above(0), "s", "that window (long enough to average out a chassis' vibration)")
     .add("min_rest_s", &G::min_rest_s, atLeast(0), "s", "still this long (guard excluded) before the gyro's mean counts as its bias")
     .add("guard_s", &G::guard_s, atLeast(0), "s", "the newest part of a still period is not trusted until more follows")
     .add("time_constant_s", &G::time_constant_s, above(0), "s", "older still periods fade with this time constant")
     .add("max_bias_rad_s", &G::max_bias_rad_s, above(0), "rad/s", "a larger mean rate while still is refused as a bias")
     .add("initial_sigma_rad_s", &G::initial_sigma_rad_s, atLeast(0), "rad/s", "the bias's sigma before a stop measured it (widens the gyro rotation's sigma)");
    return t;
  }();
  return table;
}

void GyroBiasEstimator::observe(const std::vector<ImuSample>& imu, std::int64_t t0, std::int64_t t1,
                                const Eigen::Isometry3d& step, bool step_valid) {
  Interval s{t0, t1};
  for (const ImuSample& m : imu)
    if (m.utime > t0 && m.utime <= t1 && m.gyro.allFinite() && m.accel.allFinite()) {
      s.rate_sum += m.gyro;
      s.accel_sum += m.accel;
      s.samples += 1.0;
    }
  if (s.samples <= 0.0 || !(t1 > t0)) return endPeriod();
  // The turn as the gyro sees it (bias included: ~0.02 deg a sweep): before its bias is known the lidar's own
  // rotation at rest is noisy (0.35 deg a sweep median on an idling chassis, noisy 16-beam sweeps).
  const double turned = (s.rate_sum / s.samples).norm() * toSeconds(t1 - t0);
  if (!step_valid || !(translationNorm(step) < config_.rest_translation_m) ||
      !(turned < config_.rest_rotation_deg * M_PI / 180.0))
    return endPeriod();
  if (period_.empty() && settled_.samples <= 0.0) period_start_ = t0;
  period_.push_back(s);
  if (accelerating()) return endPeriod();  // what was trusted stays in the estimate; window and guard are dropped
  update();
  settle();
}

// The intervals both before the acceleration window and older than the guard count the same way in every
// later judgement: their sums are kept instead of them, so a robot parked for hours keeps a few seconds of
// intervals, not every one.
void GyroBiasEstimator::settle() {
  const std::int64_t window_start = period_.back().t1 - toUtime(config_.window_s);
  const std::int64_t trusted_end = period_.back().t1 - toUtime(config_.guard_s);
  while (!period_.empty() && period_.front().t0 < window_start && period_.front().t1 <= trusted_end) {
    const Interval& s = period_.front();
    settled_.rate_sum += s.rate_sum;
    settled_.accel_sum += s.accel_sum;
    settled_.samples += s.samples;
    settled_.t1 = s.t1;
    period_.pop_front();
  }
}

// The mean acceleration over the newest window_s against the period's before it.
bool GyroBiasEstimator::accelerating() const {
  const std::int64_t window_start = period_.back().t1 - toUtime(config_.window_s);
  Eigen::Vector3d recent = Eigen::Vector3d::Zero(), before = settled_.accel_sum;
  double n_recent = 0.0, n_before = settled_.samples;
  for (const Interval& s : period_) {
    const bool in_window = s.t0 >= window_start;
    (in_window ? recent : before) += s.accel_sum;
    (in_window ? n_recent : n_before) += s.samples;
  }
  // Judged once the period before the window is a window long too (both means average the vibration).
  if (n_recent <= 0.0 || n_before <= 0.0 || toSeconds(window_start - period_start_) < config_.window_s) return false;
  return (recent / n_recent - before / n_before).norm() > config_.accel_tolerance_mps2;
}

// The period so far without its newest guard_s, blended with the estimate from before it. A period's mean
// rate errs by the chassis' net rotation over it divided by its length (an idling engine rocks it by a
// fraction of a degree) and by the gyro's noise: the first dominates, so a period weighs by its length
// squared, inverse to that error's variance.
void GyroBiasEstimator::update() {
  const std::int64_t trusted_end = period_.back().t1 - toUtime(config_.guard_s);
  Eigen::Vector3d sum = settled_.rate_sum;
  double samples = settled_.samples;
  std::int64_t end = settled_.samples > 0.0 ? settled_.t1 : period_start_;
  for (const Interval& s : period_) {
    if (s.t1 > trusted_end) break;
    sum += s.rate_sum;
    samples += s.samples;
    end = s.t1;
  }
  const double length = toSeconds(end - period_start_);
  if (samples <= 0.0 || length < config_.min_rest_s) return;
  const Eigen::Vector3d mean = sum / samples;
  if (!(mean.norm() <= config_.max_bias_rad_s)) return;
  if (!counted_) {
    // A new period: what came before fades with the time since it was measured.
    base_ = bias_;
    base_weight_ = weight_ > 0.0 ? weight_ * std::exp(-toSeconds(period_start_ - base_utime_) / config_.time_constant_s) : 0.0;
    counted_ = true;
    ++periods_;
  }
  const double weight = length * length;
  weight_ = base_weight_ + weight;
  bias_ = (base_ * base_weight_ + mean * weight) / weight_;
  base_utime_ = end;
}

void GyroBiasEstimator::endPeriod() {
  period_.clear();
  settled_ = Interval{};
  counted_ = false;
}

double GyroBiasEstimator::rotationSigma(double sigma_rad, double interval_s) const {
  if (known()) return sigma_rad;
  const double bias = config_.initial_sigma_rad_s * interval_s;
  return std::sqrt(sigma_rad * sigma_rad + bias * bias);
}

std::vector<ImuSample> withoutGyroBias(std::vector<ImuSample> imu, const Eigen::Vector3d& bias) {
  for (ImuSample& s : imu) s.gyro -= bias;
  return imu;
}

}  // namespace adit
