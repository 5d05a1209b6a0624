// Wheel or track odometry as the motion along directions the lidar cannot observe (issue 16: "degenerate
// directions are carried, not guessed"). Scan-to-scan odometry holds each degenerate eigen-direction of its
// registration to a motion prior (registration/solver.hpp); without wheels that prior is the lidar's own
// averaged velocity, which in a long featureless roadway is all there is and decays as the axis fades from
// view. With WHEEL_ODOM the prior is what the drive measured over the sweep interval, so the estimate keeps
// moving with the robot however long the roadway is smooth.
//
// The wheel is not trusted blindly:
//  - scale (slip): tracks turn 3-8 % faster than the ground moves. Where the lidar does observe the forward
//    motion (registration not degenerate), the ratio of the lidar's distance to the wheel's is averaged over
//    scale_distance_m of travel, and the wheel's speed is multiplied by it;
//  - disagreement: where both observe the motion and the wheel's calibrated distance differs from the lidar's
//    by more than max_disagreement (a spinning track, a wrong reading) the wheel is distrusted for distrust_s;
//  - stuck: a speed that does not change by a single bit for stuck_after_s while the lidar sees the robot move
//    is a frozen driver, distrusted until it changes;
//  - coverage: readings must span the sweep interval without a gap above max_gap_s; non-finite or unordered
//    readings (the runtime's input checks refuse them first: invalid_nonfinite, time_backwards) are skipped.
// Each case is counted (WheelCounters) and the odometry falls back to its own prior for that sweep.
//
// Frame: the base's x axis is the lidar's rotated by mount_rpy_deg (R_lidar_base); the lidar sits on the
// base's yaw axis, so a turn on the spot does not translate it. Motion is integrated in the plane of the base
// (its pitch over one sweep is negligible). Deterministic: a function of the readings and the lidar's results.
#pragma once

#include "core/config_table.hpp"
#include "core/types.hpp"
#include "core/wheel_odom.hpp"

#include <optional>
#include <vector>

namespace adit {

struct WheelMotionConfig {
  bool use = true;  // use WHEEL_ODOM when it arrives (a robot without it publishes nothing: no effect)
  // Rotation R_lidar_base as [roll, pitch, yaw] (deg): where the base's forward axis lies in the lidar frame.
  Eigen::Vector3f mount_rpy_deg = Eigen::Vector3f::Zero();
  // 1-sigma of a reading when the message says 0 (unknown), and of the calibrated scale: what the hold's
  // covariance is made of (speed_sigma / sqrt(readings) + scale_sigma * distance per sweep).
  double speed_sigma = 0.05;
  double scale_sigma = 0.01;
  // Slip calibration: the lidar/wheel distance ratio averaged over this much travel, from sweeps where the
  // registration observes every translation direction and the robot moves at least min_calibration_speed.
  // Before any calibration the scale is 1 with scale_sigma_uncalibrated.
  double scale_distance_m = 30.0;
  // How well the lidar must observe the translation for a sweep to calibrate: its weakest eigenvalue over its
  // largest (the registration's degeneracy analysis). Below calibration_min_ratio nothing, full weight from
  // calibration_full_ratio on. A barely observed axis is pulled toward zero motion (points on smooth walls
  // slide with the sensor): calibrating there put the scale 2.8 % low in tests/pipeline test_featureless_sim.
  // Disagreements are judged only at full weight.
  double calibration_min_ratio = 0.04;
  double calibration_full_ratio = 0.1;
  double min_calibration_speed = 0.2;
  double scale_sigma_uncalibrated = 0.08;
  // Relative difference of the calibrated wheel distance from the lidar's beyond which they disagree.
  double max_disagreement = 0.25;
  double distrust_s = 2.0;
  double stuck_after_s = 1.0;
  double min_moving_speed = 0.1;  // m/s the lidar must see for a constant speed to count as stuck
  double max_gap_s = 0.1;
};

// Keys "odometry.wheel.*".
const ConfigTable<WheelMotionConfig>& wheelMotionConfigTable();

// What happened to the wheel readings so far (STATUS counters of the odometry).
struct WheelCounters {
  std::int64_t used = 0;          // sweeps whose degenerate directions took the wheel's motion
  std::int64_t calibrations = 0;  // sweeps that updated the scale
  std::int64_t gaps = 0;          // sweeps the readings did not cover
  std::int64_t nonfinite = 0;     // readings skipped
  std::int64_t unordered = 0;
  std::int64_t stuck = 0;         // sweeps with a frozen speed while the lidar saw motion
  std::int64_t disagreements = 0; // sweeps where wheel and lidar disagreed
  std::int64_t distrusted = 0;    // sweeps the wheel was not used because of one of the above
};

// The wheel's motion over one sweep interval: T_prev_curr of the lidar and the 1-sigma of its translation.
struct WheelMotionEstimate {
  Eigen::Isometry3d T_prev_curr = Eigen::Isometry3d::Identity();
  double sigma_translation_m = 0.0;
  double distance_m = 0.0;  // calibrated, signed along the forward axis
  double raw_distance_m = 0.0;  // before calibration
};

class WheelMotion {
 public:
  explicit WheelMotion(WheelMotionConfig config = {});

  // The lidar's motion from t0 to t1 according to the readings (any order of coverage, checked here), or
  // nothing when they do not cover the interval or are distrusted. `rotation`: a better rotation over the
  // interval (the IMU's), replacing the wheel's yaw.
  std::optional<WheelMotionEstimate> motion(const std::vector<WheelOdomSample>& readings, std::int64_t t0,
                                            std::int64_t t1,
                                            const std::optional<Eigen::Matrix3d>& rotation = std::nullopt);

  // After the sweep was registered: the lidar's T_prev_curr and how well it observed the translation (its
  // weakest over its largest eigenvalue; 0 when degenerate). Updates the scale, or flags a disagreement.
  // `wheel` is what motion() gave.
  void observe(const Eigen::Isometry3d& lidar_T_prev_curr, double observed_ratio, double interval_s,
               const std::optional<WheelMotionEstimate>& wheel);

  double scale() const { return scale_; }
  bool calibrated() const { return calibrated_distance_m_ > 0.0; }
  const WheelCounters& counters() const { return counters_; }
  void reset();

 private:
  WheelMotionConfig config_;
  Eigen::Matrix3d R_lidar_base_ = Eigen::Matrix3d::Identity();
  double scale_ = 1.0;
  double calibrated_distance_m_ = 0.0;  // travel the scale was averaged over (capped at scale_distance_m)
  std::int64_t distrust_until_ = -1;    // utime before which the wheel is not used
  // Stuck detection: the last speed value and since when it has not changed.
  std::optional<double> last_speed_;
  std::int64_t unchanged_since_ = -1;
  std::int64_t last_t1_ = -1;
  bool frozen_ = false;       // the current interval's speed has not changed for stuck_after_s
  bool lidar_moving_ = false; // the last sweep that observed the translation saw the robot move
  WheelCounters counters_;
};

}  // namespace adit
