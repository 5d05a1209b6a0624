// One reading of wheel or track odometry (adit::wheel_odom_t): the base's forward speed and yaw rate.
// Apart from core/types.hpp so that the many files that include it need not know about wheels.
#pragma once

#include <cstdint>

namespace adit {

struct WheelOdomSample {
  std::int64_t utime = 0;
  double speed = 0.0;           // m/s along the base's x axis
  double yaw_rate = 0.0;        // rad/s about the base's z axis
  double speed_sigma = 0.0;     // 1-sigma as the drive reports it; 0 = unknown
  double yaw_rate_sigma = 0.0;
};

// PoseEstimate::flags bit (odometry_t.FLAG_HELD_TO_WHEEL): degenerate directions took the wheel's motion.
constexpr std::int32_t kPoseHeldToWheel = 128;

}  // namespace adit
