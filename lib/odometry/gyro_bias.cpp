#include "odometry/gyro_bias.hpp"

#include "core/geometry.hpp"

#include <cmath>
#include <limits>

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
     .add("rocking_correlation_s", &G::rocking_correlation_s, atLeast(0), "s", "correlation time of the chassis' rocking at rest (a still period's slope variance: 12 r^2 this / L^3)")
     .add("noise_density_rad_s_sqrt_hz", &G::noise_density_rad_s_sqrt_hz, above(0), "rad/s/sqrt(Hz)", "the gyro's white noise density (a still period's slope variance: this^2 / L)")
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
  if (period_.empty() && settled_.samples <= 0.0) {
    period_start_ = t0;
    theta_ = Eigen::Array3d::Zero();
    last_sample_utime_ = t0;
  }
  integrate(imu, s);
  period_.push_back(s);
  if (accelerating()) return endPeriod();  // what was trusted stays in the estimate; window and guard are dropped
  update();
  settle();
}

// The angle the gyro turned since the period's start, sample by sample, into the interval's sums.
void GyroBiasEstimator::integrate(const std::vector<ImuSample>& imu, Interval& s) {
  for (const ImuSample& m : imu) {
    if (!(m.utime > s.t0 && m.utime <= s.t1 && m.gyro.allFinite() && m.accel.allFinite())) continue;
    theta_ += m.gyro.array() * toSeconds(m.utime - last_sample_utime_);
    last_sample_utime_ = m.utime;
    const double t = toSeconds(m.utime - period_start_);
    s.t_sum += t;
    s.t_sq_sum += t * t;
    s.theta_sum += theta_;
    s.theta_sq_sum += theta_ * theta_;
    s.theta_t_sum += theta_ * t;
  }
}

void GyroBiasEstimator::Interval::add(const Interval& o) {
  accel_sum += o.accel_sum;
  samples += o.samples;
  t_sum += o.t_sum;
  t_sq_sum += o.t_sq_sum;
  theta_sum += o.theta_sum;
  theta_sq_sum += o.theta_sq_sum;
  theta_t_sum += o.theta_t_sum;
  t1 = o.t1;
}

// Least squares line theta = a + rate t. The residual is the rocking about the attitude the chassis rests
// at, correlated over rocking_correlation_s rather than from sample to sample: its effect on the slope is
// that of L / rocking_correlation_s independent samples.
GyroBiasEstimator::Slope GyroBiasEstimator::fit(const Interval& sums, double length_s) const {
  Slope out;
  const double n = sums.samples;
  const double sxx = sums.t_sq_sum - sums.t_sum * sums.t_sum / n;
  if (!(n > 2.0) || !(sxx > 0.0) || !(length_s > 0.0)) {
    out.variance = Eigen::Array3d::Constant(std::numeric_limits<double>::infinity());
    return out;
  }
  const Eigen::Array3d sxy = sums.theta_t_sum - sums.theta_sum * (sums.t_sum / n);
  const Eigen::Array3d syy = sums.theta_sq_sum - sums.theta_sum * sums.theta_sum / n;
  out.rate = sxy / sxx;
  const Eigen::Array3d residual_sq = ((syy - sxy * sxy / sxx) / n).max(0.0);
  const double nd = config_.noise_density_rad_s_sqrt_hz;
  out.variance = residual_sq * (12.0 * config_.rocking_correlation_s / (length_s * length_s * length_s)) + nd * nd / length_s;
  return out;
}

// The intervals both before the acceleration window and older than the guard count the same way in every
// later judgement: their sums are kept instead of them, so a robot parked for hours keeps a few seconds of
// intervals, not every one.
void GyroBiasEstimator::settle() {
  const std::int64_t window_start = period_.back().t1 - toUtime(config_.window_s);
  const std::int64_t trusted_end = period_.back().t1 - toUtime(config_.guard_s);
  while (!period_.empty() && period_.front().t0 < window_start && period_.front().t1 <= trusted_end) {
    settled_.add(period_.front());
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

// The period so far without its newest guard_s, its slope blended with the estimate from before it.
void GyroBiasEstimator::update() {
  const std::int64_t trusted_end = period_.back().t1 - toUtime(config_.guard_s);
  Interval trusted = settled_;
  if (trusted.samples <= 0.0) trusted.t1 = period_start_;
  for (const Interval& s : period_) {
    if (s.t1 > trusted_end) break;
    trusted.add(s);
  }
  const double length = toSeconds(trusted.t1 - period_start_);
  if (trusted.samples <= 0.0 || length < config_.min_rest_s) return;
  const Slope slope = fit(trusted, length);
  if (!(slope.rate.matrix().norm() <= config_.max_bias_rad_s) || !slope.variance.isFinite().all()) return;
  if (!counted_) {
    // A new period: what came before fades with the time since it was measured.
    base_ = mean_;
    base_weight_ = periods_ > 0 ? Eigen::Array3d(weight_ * std::exp(-toSeconds(period_start_ - base_utime_) / config_.time_constant_s))
                                : Eigen::Array3d::Zero();
    counted_ = true;
    ++periods_;
  }
  const Eigen::Array3d weight = slope.variance.inverse();
  weight_ = base_weight_ + weight;
  mean_ = (base_ * base_weight_ + slope.rate * weight) / weight_;
  base_utime_ = trusted.t1;
}

void GyroBiasEstimator::endPeriod() {
  period_.clear();
  settled_ = Interval{};
  counted_ = false;
}

// The turn-on bias: a prior of zero with sigma initial_sigma_rad_s, blended with the periods' slopes by
// their weights (0 = no prior: the periods alone).
double GyroBiasEstimator::priorWeight() const {
  const double s = config_.initial_sigma_rad_s;
  return s > 0.0 ? 1.0 / (s * s) : 0.0;
}

Eigen::Vector3d GyroBiasEstimator::bias() const {
  if (!known()) return Eigen::Vector3d::Zero();
  return (mean_ * weight_ / (weight_ + priorWeight())).matrix();
}

double GyroBiasEstimator::biasSigma() const {
  if (!known()) return config_.initial_sigma_rad_s;
  return 1.0 / std::sqrt((weight_ + priorWeight()).minCoeff());
}

double GyroBiasEstimator::rotationSigma(double sigma_rad, double interval_s) const {
  const double bias = biasSigma() * interval_s;
  return std::sqrt(sigma_rad * sigma_rad + bias * bias);
}

std::vector<ImuSample> withoutGyroBias(std::vector<ImuSample> imu, const Eigen::Vector3d& bias) {
  for (ImuSample& s : imu) s.gyro -= bias;
  return imu;
}

}  // namespace adit
