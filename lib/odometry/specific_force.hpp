// The accelerometer between two sweeps, preintegrated for a later stage: the specific force of each sample,
// rotated into the lidar frame at the interval's end, integrated once and twice (core/types.hpp's
// SpecificForceIntegral, carried on ODOM_SCAN). The odometry does this because it has the IMU; the mapper,
// whose rotations are held by the map and do not follow a gyro's walking bias, turns it into gravity
// (mapping/gravity.hpp).
#pragma once

#include "core/types.hpp"

#include <vector>

namespace adit {

// Samples in (since, utime] (raw, IMU frame, in time order; others are skipped), each sample's force counting
// from the sample before it (from `since` for the first; the last one's also up to `utime`). The lidar's rotation inside the interval is
// interpolated from R_curr_prev (the lidar at `since` seen from the lidar at `utime`). None (since_utime -1)
// when the samples leave a gap longer than max_gap_s, at either end too, or a reading is not finite.
SpecificForceIntegral integrateSpecificForce(const std::vector<ImuSample>& imu, std::int64_t since,
                                             std::int64_t utime, const Eigen::Matrix3d& R_curr_prev,
                                             const Eigen::Quaterniond& R_lidar_imu, double max_gap_s);

}  // namespace adit
