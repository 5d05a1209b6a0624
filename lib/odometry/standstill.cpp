#include "odometry/standstill.hpp"

#include "core/geometry.hpp"

#include <algorithm>
#include <cmath>

namespace adit {

ConfigTable<StandstillConfig> standstillConfigTable(const std::string& prefix) {
  using S = StandstillConfig;
  ConfigTable<S> t(prefix);
  t.add("window_sweeps", &S::window_sweeps, between(0, 10000), "sweeps", "registrations a line is fitted through to tell that the robot stands (0: never hold the position)")
   .add("max_speed_mps", &S::max_speed_mps, above(0), "m/s", "the robot stands while the line's translation slope is below this (and its rotation slope below max_rate_rad_s)")
   .add("max_rate_rad_s", &S::max_rate_rad_s, above(0), "rad/s", "the robot stands while the line's rotation slope is below this (and its translation slope below max_speed_mps)")
   .add("leave_sweeps", &S::leave_sweeps, between(1, 10000), "sweeps", "a hold ends when the mean of this many newest registrations departs from the held position or rotation")
   .add("leave_distance_m", &S::leave_distance_m, above(0), "m", "least departure of the newest registrations' mean that ends a hold (more where they scatter more: leave_sigmas)")
   .add("leave_sigmas", &S::leave_sigmas, atLeast(0), "", "a hold also needs a departure of this many times the held registrations' RMS scatter over the root of leave_sweeps")
   .add("leave_angle_rad", &S::leave_angle_rad, above(0), "rad", "the newest registrations' mean turned this far from the held ones' mean rotation ends a hold");
  return t;
}

StandstillHold::Sample StandstillHold::sample(std::int64_t utime, const Eigen::Isometry3d& T) const {
  return {utime, T.translation() - anchor_, logRotation(reference_.transpose() * T.linear())};
}

Eigen::Isometry3d StandstillHold::update(std::int64_t utime, const Eigen::Isometry3d& registered) {
  if (config_.window_sweeps <= 0) return registered;
  if (window_.empty()) {
    anchor_ = registered.translation();
    reference_ = registered.linear();
  }
  window_.push_back(sample(utime, registered));
  if (static_cast<int>(window_.size()) > config_.window_sweeps) {
    window_.pop_front();
    if (!holding_) reanchor();
  }
  if (holding_) {
    add(window_.back());
    if (departed() || !windowStill()) {
      reset();
      return registered;
    }
    return held(registered);
  }
  if (static_cast<int>(window_.size()) < config_.window_sweeps || !windowStill()) return registered;
  holding_ = true;
  for (const Sample& s : window_) add(s);
  return held(registered);
}

// The window's first sample becomes the anchor, so that positions and rotation vectors stay small however
// far the robot drives (a rotation vector wraps at 180 deg).
void StandstillHold::reanchor() {
  const Eigen::Vector3d shift = window_.front().position;
  const Eigen::Matrix3d turn = expRotation(window_.front().rotation);  // new reference in the old one
  for (Sample& s : window_) {
    s.position -= shift;
    s.rotation = logRotation(turn.transpose() * expRotation(s.rotation));
  }
  anchor_ += shift;
  reference_ = reference_ * turn;
}

void StandstillHold::add(const Sample& s) {
  position_sum_ += s.position;
  position_sq_sum_ += s.position.squaredNorm();
  rotation_sum_ += s.rotation;
  ++held_count_;
}

// The least-squares slopes of position and rotation against time over the window, each below its bound.
bool StandstillHold::windowStill() const {
  // Times in seconds since the window's first sample.
  const auto seconds = [this](const Sample& s) { return toSeconds(s.utime - window_.front().utime); };
  double t_mean = 0;
  Eigen::Vector3d p_mean = Eigen::Vector3d::Zero(), r_mean = Eigen::Vector3d::Zero();
  for (const Sample& s : window_) {
    t_mean += seconds(s);
    p_mean += s.position;
    r_mean += s.rotation;
  }
  const double n = static_cast<double>(window_.size());
  t_mean /= n;
  p_mean /= n;
  r_mean /= n;
  double tt = 0;
  Eigen::Vector3d tp = Eigen::Vector3d::Zero(), tr = Eigen::Vector3d::Zero();
  for (const Sample& s : window_) {
    const double dt = seconds(s) - t_mean;
    tt += dt * dt;
    tp += dt * (s.position - p_mean);
    tr += dt * (s.rotation - r_mean);
  }
  if (tt <= 0) return false;  // all at one time: no slope to judge
  return (tp / tt).norm() < config_.max_speed_mps && (tr / tt).norm() < config_.max_rate_rad_s;
}

// The mean of the newest registrations against the held mean. The distance bound scales with the held
// registrations' own scatter (their RMS distance from the mean, divided by the root of how many are averaged):
// a quiet chassis and a clean lidar scatter by ~4 mm and a start shows at ~1 cm, an idling one scatters by
// twice that and must not end the hold.
bool StandstillHold::departed() const {
  const int k = std::min<int>(config_.leave_sweeps, static_cast<int>(window_.size()));
  Eigen::Vector3d p = Eigen::Vector3d::Zero(), r = Eigen::Vector3d::Zero();
  for (int i = 0; i < k; ++i) {
    p += window_[window_.size() - 1 - i].position;
    r += window_[window_.size() - 1 - i].rotation;
  }
  p /= k;
  r /= k;
  const Eigen::Vector3d mean = position_sum_ / held_count_;
  const double scatter = std::sqrt(std::max(0.0, position_sq_sum_ / held_count_ - mean.squaredNorm()));
  const double bound = std::max(config_.leave_distance_m, config_.leave_sigmas * scatter / std::sqrt(k));
  return (p - mean).norm() > bound || (r - rotation_sum_ / held_count_).norm() > config_.leave_angle_rad;
}

Eigen::Isometry3d StandstillHold::held(const Eigen::Isometry3d& registered) const {
  Eigen::Isometry3d T = registered;
  T.translation() = anchor_ + position_sum_ / held_count_;
  return T;
}

void StandstillHold::reset() {
  window_.clear();
  holding_ = false;
  position_sum_.setZero();
  position_sq_sum_ = 0;
  rotation_sum_.setZero();
  held_count_ = 0;
}

// Positions are kept relative to anchor_ and rotations relative to reference_: the correction moves the
// anchor and turns the relative positions and the reference; rotation vectors relative to a reference that
// turns with them stay as they are (reference_ * exp(r) becomes R * reference_ * exp(r)).
void StandstillHold::applyCorrection(const Eigen::Isometry3d& T) {
  anchor_ = T * anchor_;
  for (Sample& s : window_) s.position = T.linear() * s.position;
  position_sum_ = T.linear() * position_sum_;
  reference_ = T.linear() * reference_;
}

}  // namespace adit
