#include "odometry/wheel_motion.hpp"

#include "features/feature_config.hpp"

#include <algorithm>
#include <cmath>

namespace adit {
namespace {

// A reading's speed and yaw rate at time t by linear interpolation (held before the first and after the last).
struct Rates {
  double speed = 0.0, yaw_rate = 0.0;
};

Rates ratesAt(const std::vector<const WheelOdomSample*>& r, std::int64_t t) {
  if (t <= r.front()->utime) return {r.front()->speed, r.front()->yaw_rate};
  if (t >= r.back()->utime) return {r.back()->speed, r.back()->yaw_rate};
  const auto next = std::upper_bound(r.begin(), r.end(), t, [](std::int64_t u, const WheelOdomSample* s) { return u < s->utime; });
  const WheelOdomSample& b = **next;
  const WheelOdomSample& a = **(next - 1);
  const double f = static_cast<double>(t - a.utime) / static_cast<double>(std::max<std::int64_t>(1, b.utime - a.utime));
  return {a.speed + f * (b.speed - a.speed), a.yaw_rate + f * (b.yaw_rate - a.yaw_rate)};
}

}  // namespace

const ConfigTable<WheelMotionConfig>& wheelMotionConfigTable() {
  using W = WheelMotionConfig;
  static const ConfigTable<W> table = [] {
    ConfigTable<W> t("odometry.wheel");
    t.add("use", &W::use, anyValue(), "", "hold degenerate directions to WHEEL_ODOM when it arrives")
     .add("mount_rpy_deg", &W::mount_rpy_deg, between(-360, 360), "deg", "rotation R_lidar_base as [roll, pitch, yaw]: the base's forward axis in the lidar frame")
     .add("speed_sigma", &W::speed_sigma, above(0), "m/s", "1-sigma of a reading whose message gives none")
     .add("scale_sigma", &W::scale_sigma, above(0), "", "1-sigma of the calibrated slip scale")
     .add("scale_distance_m", &W::scale_distance_m, above(0), "m", "travel the lidar/wheel distance ratio (slip) is averaged over")
     .add("min_calibration_speed", &W::min_calibration_speed, atLeast(0), "m/s", "slower sweeps do not calibrate the scale")
     .add("calibration_min_ratio", &W::calibration_min_ratio, between(0, 1), "", "translation eigenvalue ratio below which a sweep does not calibrate the slip")
     .add("calibration_full_ratio", &W::calibration_full_ratio, between(0, 1), "", "ratio from which a sweep calibrates with full weight (and disagreements are judged)")
     .add("scale_sigma_uncalibrated", &W::scale_sigma_uncalibrated, above(0), "", "1-sigma of the scale before any calibration")
     .add("max_disagreement", &W::max_disagreement, above(0), "", "relative difference of wheel and lidar distance beyond which the wheel is distrusted")
     .add("distrust_s", &W::distrust_s, atLeast(0), "s", "how long a disagreement keeps the wheel out")
     .add("stuck_after_s", &W::stuck_after_s, above(0), "s", "a speed unchanged this long while the robot moves is a frozen reading")
     .add("min_moving_speed", &W::min_moving_speed, atLeast(0), "m/s", "lidar speed above which the robot counts as moving (stuck check)")
     .add("max_gap_s", &W::max_gap_s, above(0), "s", "largest gap between readings over a sweep interval");
    return t;
  }();
  return table;
}

WheelMotion::WheelMotion(WheelMotionConfig config)
    : config_(std::move(config)), R_lidar_base_(rotationFromRpyDeg(config_.mount_rpy_deg).toRotationMatrix()) {}

void WheelMotion::reset() {
  const WheelCounters counters = counters_;
  *this = WheelMotion(config_);
  counters_ = counters;
}

std::optional<WheelMotionEstimate> WheelMotion::motion(const std::vector<WheelOdomSample>& readings, std::int64_t t0,
                                                       std::int64_t t1, const std::optional<Eigen::Matrix3d>& rotation) {
  if (!config_.use || readings.empty() || t1 <= t0) return std::nullopt;
  const std::int64_t max_gap = toUtime(config_.max_gap_s);
  // The usable readings around the interval: finite, strictly increasing in time.
  std::vector<const WheelOdomSample*> r;
  for (const WheelOdomSample& s : readings) {
    if (s.utime < t0 - max_gap || s.utime > t1 + max_gap) continue;
    const bool fresh = s.utime > last_t1_;  // counted once, not again by the next sweep
    if (!std::isfinite(s.speed) || !std::isfinite(s.yaw_rate)) {
      if (fresh) ++counters_.nonfinite;
      continue;
    }
    if (!r.empty() && s.utime <= r.back()->utime) {
      if (fresh) ++counters_.unordered;
      continue;
    }
    r.push_back(&s);
    // Stuck detection: since when has the speed not changed by a single bit?
    if (fresh && s.utime > t0) {
      if (!last_speed_ || *last_speed_ != s.speed) unchanged_since_ = s.utime;
      last_speed_ = s.speed;
    }
  }
  last_t1_ = std::max(last_t1_, t1);
  bool covered = !r.empty() && r.front()->utime <= t0 + max_gap && r.back()->utime >= t1 - max_gap;
  for (std::size_t i = 1; covered && i < r.size(); ++i) covered = r[i]->utime - r[i - 1]->utime <= max_gap;
  if (!covered) {
    ++counters_.gaps;
    return std::nullopt;
  }
  frozen_ = unchanged_since_ >= 0 && toSeconds(t1 - unchanged_since_) >= config_.stuck_after_s;
  // A constant non-zero speed while moving is a frozen driver (a real encoder's value jitters); a constant
  // zero is one only when the lidar saw the robot move.
  if (frozen_ && (*last_speed_ != 0.0 || lidar_moving_)) {
    ++counters_.stuck;
    ++counters_.distrusted;
    return std::nullopt;
  }
  if (t1 < distrust_until_) {
    ++counters_.distrusted;
    return std::nullopt;
  }
  // Integrate in the base's plane: breakpoints at t0, every reading inside, t1; midpoint heading per step.
  std::vector<std::int64_t> times{t0};
  for (const WheelOdomSample* s : r)
    if (s->utime > t0 && s->utime < t1) times.push_back(s->utime);
  times.push_back(t1);
  Eigen::Vector3d p = Eigen::Vector3d::Zero();
  double heading = 0.0, raw = 0.0, speed_var = 0.0;
  for (std::size_t i = 1; i < times.size(); ++i) {
    const Rates a = ratesAt(r, times[i - 1]), b = ratesAt(r, times[i]);
    const double dt = toSeconds(times[i] - times[i - 1]);
    const double v = 0.5 * (a.speed + b.speed), w = 0.5 * (a.yaw_rate + b.yaw_rate);
    const double mid = heading + 0.5 * w * dt;
    p += scale_ * v * dt * Eigen::Vector3d(std::cos(mid), std::sin(mid), 0.0);
    raw += v * dt;
    heading += w * dt;
  }
  for (const WheelOdomSample* s : r) {
    const double sigma = s->speed_sigma > 0.0 ? s->speed_sigma : config_.speed_sigma;
    speed_var += sigma * sigma;
  }
  const double interval = toSeconds(t1 - t0);
  // Readings' noise averages over the interval; the scale's error does not.
  const double noise = std::sqrt(speed_var) / static_cast<double>(r.size()) * interval;
  const double scale_sigma = calibrated() ? config_.scale_sigma : config_.scale_sigma_uncalibrated;
  WheelMotionEstimate out;
  out.raw_distance_m = raw;
  out.distance_m = scale_ * raw;
  out.sigma_translation_m = std::sqrt(noise * noise + std::pow(scale_sigma * out.distance_m, 2)) + 1e-4;
  const Eigen::Matrix3d R_base = Eigen::AngleAxisd(heading, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  out.T_prev_curr.linear() = rotation ? *rotation : Eigen::Matrix3d(R_lidar_base_ * R_base * R_lidar_base_.transpose());
  out.T_prev_curr.translation() = R_lidar_base_ * p;
  ++counters_.used;
  return out;
}

void WheelMotion::observe(const Eigen::Isometry3d& lidar, double observed_ratio, double interval_s,
                          const std::optional<WheelMotionEstimate>& wheel) {
  if (!(interval_s > 0.0)) return;
  const double lidar_forward = (R_lidar_base_.transpose() * lidar.translation()).x();
  const double lidar_speed = std::abs(lidar_forward) / interval_s;
  const double span = std::max(1e-9, config_.calibration_full_ratio - config_.calibration_min_ratio);
  const double weight = std::clamp((observed_ratio - config_.calibration_min_ratio) / span, 0.0, 1.0);
  if (weight >= 1.0) lidar_moving_ = lidar_speed >= config_.min_moving_speed;
  if (!wheel || !(weight > 0.0) || lidar_speed < config_.min_calibration_speed) return;
  // Both observe the motion well: do they agree (after calibration, or within the worst slip before it)?
  if (weight >= 1.0 &&
      std::abs(wheel->distance_m - lidar_forward) > config_.max_disagreement * std::abs(lidar_forward)) {
    ++counters_.disagreements;
    distrust_until_ = last_t1_ + toUtime(config_.distrust_s);
    return;
  }
  if (!(std::abs(wheel->raw_distance_m) > 0.0)) return;
  // Distance-weighted running mean that turns into an exponential average over scale_distance_m.
  const double ratio = lidar_forward / wheel->raw_distance_m;
  if (std::abs(ratio - 1.0) > config_.max_disagreement) return;  // weakly observed and implausible
  const double distance = weight * std::abs(wheel->raw_distance_m);
  calibrated_distance_m_ = std::min(config_.scale_distance_m, calibrated_distance_m_ + distance);
  scale_ += distance / calibrated_distance_m_ * (ratio - scale_);
  ++counters_.calibrations;
}

}  // namespace adit
