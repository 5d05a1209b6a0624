// A robot that stands still keeps one pose. Each sweep's registration errs by a few millimetres and tenths of
// a degree (range noise, which points a sweep picks, an idling chassis' rocking), so a pose that follows
// every registration wanders while the robot waits (16-26 mm in a minute on a noisy 16-beam lidar, issue 16),
// and each sweep entering the map at its wandering pose thickens the surfaces round the stop.
//
// StandstillHold watches the stream of registered poses. The robot stands when a least-squares line through
// the last window_sweeps positions (and rotation vectors) rises slower than max_speed_mps (max_rate_rad_s):
// at rest the slope of 2 s of registrations stays within ~5 mm/s and ~0.15 deg/s with a noisy lidar and an
// idling chassis, while a robot creeping at 1 cm/s moves 2 cm in those 2 s. From then on the pose is the mean
// of the registrations since the window began (error shrinking with their number; the rotation stays each
// registration's own, as an idling chassis really rocks by tenths of a degree and the lidar sees it), and the
// caller leaves the map as it is. The hold ends when the mean of the newest leave_sweeps registrations departs
// from the held position by leave_distance_m, or by leave_sigmas times the held registrations' own scatter
// over the root of leave_sweeps where that is more (an idling chassis and a noisy lidar scatter by ~7 mm, and
// the mean of three stays within ~13 mm; a quiet one by ~4 mm), or turns by leave_angle_rad; a new hold needs a
// full still window again. A vehicle pulling away is let go within about half a second, 2-4 cm on (0.3 m/s^2).
// Deterministic: the output depends only on the poses given, in order.
#pragma once

#include "core/config_table.hpp"
#include "core/types.hpp"

#include <deque>

namespace adit {

struct StandstillConfig {
  int window_sweeps = 20;  // 0: never hold (every registration is the pose)
  double max_speed_mps = 0.01;
  double max_rate_rad_s = 0.005;  // 0.3 deg/s
  int leave_sweeps = 3;
  double leave_distance_m = 0.008;
  double leave_sigmas = 5.0;
  double leave_angle_rad = 0.0105;  // 0.6 deg
};

// Keys "<prefix>.*" ("mapping.standstill", "odometry.standstill").
ConfigTable<StandstillConfig> standstillConfigTable(const std::string& prefix);

class StandstillHold {
 public:
  explicit StandstillHold(StandstillConfig config = {}) : config_(config) {}

  // The registered pose T_world_lidar of the sweep at utime (in time order). Returns the pose to report:
  // `registered` itself while the robot moves; while it stands, `registered` with the mean position of the
  // still registrations.
  Eigen::Isometry3d update(std::int64_t utime, const Eigen::Isometry3d& registered);
  // True from the sweep that started a hold until the one that ended it.
  bool holding() const { return holding_; }
  // A registration failed, or the robot was put somewhere else: the next hold needs a full window again.
  void reset();
  // A loop closure moved the trajectory: what was held moves with it.
  void applyCorrection(const Eigen::Isometry3d& T_corrected_uncorrected);

 private:
  struct Sample {
    std::int64_t utime = 0;
    Eigen::Vector3d position, rotation;  // relative to anchor_ and to reference_ (rotation vector)
  };
  Sample sample(std::int64_t utime, const Eigen::Isometry3d& T) const;
  bool windowStill() const;
  bool departed() const;
  void add(const Sample& s);  // into the held mean
  void reanchor();
  Eigen::Isometry3d held(const Eigen::Isometry3d& registered) const;

  StandstillConfig config_;
  std::deque<Sample> window_;
  Eigen::Vector3d anchor_ = Eigen::Vector3d::Zero();         // the window's first position
  Eigen::Matrix3d reference_ = Eigen::Matrix3d::Identity();  // and rotation
  bool holding_ = false;
  // Sums of the held registrations (position, its squared norm, rotation vector) and their count.
  Eigen::Vector3d position_sum_ = Eigen::Vector3d::Zero(), rotation_sum_ = Eigen::Vector3d::Zero();
  double position_sq_sum_ = 0;
  int held_count_ = 0;
};

}  // namespace adit
