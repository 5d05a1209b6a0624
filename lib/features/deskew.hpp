// Motion-distortion correction (deskew): every point is moved from the lidar frame at its firing time into
// the lidar frame at the sweep's reference instant (its last firing, dt = 0).
#pragma once

#include "core/types.hpp"
#include "features/feature_config.hpp"

#include <cstdint>
#include <vector>

namespace adit {

// Constant-velocity model from odometry: the motion over the previous interval, assumed to continue.
struct MotionPrior {
  Eigen::Isometry3d T_prev_curr = Eigen::Isometry3d::Identity();  // lidar at previous sweep <- lidar now
  double dt_s = 0.1;   // time between the two sweeps (s)
  bool valid = false;  // false: no motion model (first sweep, after a reset)
};

namespace features {

// Pose of the lidar at time dt (s, <= 0) expressed in the lidar frame at dt = 0, under each model.
// Constant velocity: the previous interval's motion scaled by -dt / dt_s (slerp + linear translation).
Eigen::Isometry3d motionModelPose(const MotionPrior& motion, double dt);

// Rotation of the lidar at each of `times` (s relative to end_utime, ascending, <= 0) in the lidar frame at
// end_utime, from gyro integration (trapezoidal rates between samples). Empty if the samples do not cover
// [times.front(), 0] to within max_gap_s.
std::vector<Eigen::Quaterniond> imuRotations(const std::vector<ImuSample>& imu, std::int64_t end_utime,
                                             const std::vector<double>& times, const Eigen::Quaterniond& R_lidar_imu,
                                             double max_gap_s);

// Deskews `points` in place (each uses its dt). Rotation from the IMU when its samples cover the sweep,
// otherwise from the motion prior; translation from the motion prior when valid (an IMU alone gives none).
// Returns the FeatureSet flags it applied: kDeskewImu and/or kDeskewMotion, 0 if points were not moved.
std::int32_t deskewPoints(std::vector<LidarPoint>& points, std::int64_t utime, float sweep_duration,
                          const std::vector<ImuSample>& imu, const MotionPrior& motion, const DeskewConfig& cfg);

}  // namespace features
}  // namespace adit
