#include "mapping/gravity.hpp"

#include "registration/pose_increment.hpp"

#include <Eigen/Cholesky>

#include <algorithm>
#include <cmath>

namespace adit {
namespace {
constexpr double kStandardGravity = 9.80665;  // m/s^2
}

ConfigTable<GravityConfig> gravityConfigTable(const std::string& prefix) {
  using G = GravityConfig;
  ConfigTable<G> t(prefix);
  t.add("window_s", &G::window_s, between(0, 600), "s", "span of the registered sweeps and accelerometer integrals gravity is fitted over (0: gravity is not found)")
   .add("tolerance_mps2", &G::tolerance_mps2, above(0), "m/s^2", "a fit whose gravity is further than this from 9.80665 m/s^2 is not trusted (counted gravity_rejected)")
   .add("time_constant_s", &G::time_constant_s, atLeast(0), "s", "a tilt of the map away from the down it started with decays over this (0: the tilt is not corrected)")
   .add("reference_sweeps", &G::reference_sweeps, between(1, 100000), "sweeps", "gravities averaged into the map's down before the map is levelled to it")
   .add("bias_sigma_mps2", &G::bias_sigma_mps2, above(0), "m/s^2", "prior of the accelerometer's bias, estimated where the heading changes")
   .add("max_tilt_rad", &G::max_tilt_rad, above(0), "rad", "a larger tilt between the gravity found and the map's down is not the map's drift (an accelerometer mounted otherwise than configured, or failing): not corrected, counted gravity_disagrees")
   .add("fit_sigma_mps2", &G::fit_sigma_mps2, above(0), "m/s^2", "weight of one gravity found in that estimate (consecutive windows share most sweeps)");
  return t;
}

std::optional<Eigen::Vector3d> GravityObserver::add(std::int64_t utime, const Eigen::Isometry3d& T,
                                                    const SpecificForceIntegral& force) {
  if (!(config_.window_s > 0.0) || !isFinitePose(T)) {
    reset();
    return std::nullopt;
  }
  const bool joined = !sweeps_.empty() && force.valid() && force.since_utime == sweeps_.back().utime;
  if (!joined) sweeps_.clear();  // the window starts again at this sweep
  Sweep s;
  s.utime = utime;
  s.position = T.translation();
  if (joined) {
    s.velocity_change = T.linear() * force.velocity_change;
    s.displacement = T.linear() * force.displacement;
  }
  sweeps_.push_back(s);
  const std::int64_t window = toUtime(config_.window_s);
  while (sweeps_.size() > 3 && utime - sweeps_[1].utime >= window) sweeps_.pop_front();
  if (sweeps_.size() < 3 || utime - sweeps_.front().utime < window) return std::nullopt;
  const Eigen::Vector3d g = fit();
  if (!g.allFinite() || std::abs(g.norm() - kStandardGravity) > config_.tolerance_mps2) {
    ++rejected_;
    return std::nullopt;
  }
  return g;
}

// p_i - S_i = p0 + v0 t_i + g t_i^2 / 2 by least squares over the window (t from its first sweep).
Eigen::Vector3d GravityObserver::fit() const {
  Eigen::Matrix3d normal = Eigen::Matrix3d::Zero();
  Eigen::Matrix3d rhs = Eigen::Matrix3d::Zero();  // one column per axis
  const Sweep& first = sweeps_.front();
  Eigen::Vector3d velocity = Eigen::Vector3d::Zero(), displacement = Eigen::Vector3d::Zero();  // S' and S
  std::int64_t previous = first.utime;
  for (const Sweep& s : sweeps_) {
    displacement += velocity * toSeconds(s.utime - previous) + s.displacement;  // the first's are zero
    velocity += s.velocity_change;
    previous = s.utime;
    const double t = toSeconds(s.utime - first.utime);
    const Eigen::Vector3d phi(1.0, t, 0.5 * t * t);
    normal += phi * phi.transpose();
    rhs += phi * (s.position - first.position - displacement).transpose();
  }
  return normal.ldlt().solve(rhs).row(2).transpose();
}

void GravityObserver::applyCorrection(const Eigen::Isometry3d& T) {
  if (!isFinitePose(T)) return;
  for (Sweep& s : sweeps_) {
    s.position = T * s.position;
    s.velocity_change = T.linear() * s.velocity_change;
    s.displacement = T.linear() * s.displacement;
  }
}

Eigen::Vector3d GravityReference::down() const { return kStandardGravity * down_sum_.normalized(); }

Eigen::Vector3d GravityReference::bias() const {
  const double prior = 1.0 / (config_.bias_sigma_mps2 * config_.bias_sigma_mps2);
  return (bias_normal_ + prior * Eigen::Matrix3d::Identity()).ldlt().solve(bias_rhs_);
}

std::optional<Eigen::Isometry3d> GravityReference::levelling(const std::optional<Eigen::Vector3d>& gravity_world,
                                                             const Eigen::Isometry3d& T, std::int64_t utime) {
  if (!(config_.time_constant_s > 0.0) || !known() || !gravity_world || !isFinitePose(T)) return std::nullopt;
  if (last_levelling_ < 0) last_levelling_ = utime;  // the first turn a whole window after the down is known
  if (utime - last_levelling_ < toUtime(config_.window_s)) return std::nullopt;
  last_levelling_ = utime;
  const Eigen::Vector3d unbiased = *gravity_world - (T.linear() - R_reference_) * bias();
  const Eigen::AngleAxisd tilt(Eigen::Quaterniond::FromTwoVectors(unbiased, down()));
  if (tilt.angle() > config_.max_tilt_rad) {
    ++disagreements_;
    return std::nullopt;
  }
  const double share = std::min(1.0, config_.window_s / config_.time_constant_s);
  return Eigen::Translation3d(T.translation()) * Eigen::AngleAxisd(share * tilt.angle(), tilt.axis()) *
         Eigen::Translation3d(-T.translation());
}

// The gravity found is g0 + R b, and the reference holds g0 + R0 b: (R - R0) b = found - reference.
void GravityReference::observe(const Eigen::Vector3d& gravity_world, const Eigen::Isometry3d& T) {
  if (!gravity_world.allFinite() || !(gravity_world.norm() > 0.0) || !isFinitePose(T)) return;
  if (count_ == 0) R_reference_ = T.linear();
  if (count_ < config_.reference_sweeps) {
    down_sum_ += gravity_world.normalized();
    ++count_;
    return;
  }
  const Eigen::Matrix3d D = T.linear() - R_reference_;
  const double w = 1.0 / (config_.fit_sigma_mps2 * config_.fit_sigma_mps2);
  bias_normal_ += w * D.transpose() * D;
  bias_rhs_ += w * D.transpose() * (gravity_world - down());
}

void GravityReference::restore(const State& s) {
  if (!s.down_sum.allFinite() || s.count < 0 || !s.R_reference.allFinite()) return;
  down_sum_ = s.down_sum;
  count_ = s.count;
  R_reference_ = s.R_reference;
}

}  // namespace adit
