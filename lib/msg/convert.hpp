// Conversions between the plain stage types (core/types.hpp) and the LCM messages (lcmtypes/adit).
// The only place that knows both; stages never see LCM, processes never hand-copy fields.
#pragma once

#include "core/types.hpp"
#include "core/wheel_odom.hpp"
#include "msg/point_set.hpp"

#include <adit/features_t.hpp>
#include <adit/imu_t.hpp>
#include <adit/loop_closure_t.hpp>
#include <adit/odometry_t.hpp>
#include <adit/point_cloud_t.hpp>
#include <adit/wheel_odom_t.hpp>

namespace adit::msg {

adit::header_t makeHeader(std::int64_t utime, const std::string& frame_id);

adit::point_cloud_t toMessage(const LidarScan& scan);
LidarScan fromMessage(const adit::point_cloud_t& msg);
// A bare point set (feature subsets) with the sweep's metadata.
adit::point_cloud_t toMessage(const std::vector<LidarPoint>& points, const LidarScan& like);
std::vector<LidarPoint> pointsFromMessage(const adit::point_cloud_t& msg);

adit::imu_t toMessage(const ImuSample& imu);
ImuSample fromMessage(const adit::imu_t& msg);
adit::wheel_odom_t toMessage(const WheelOdomSample& wheel);
WheelOdomSample fromMessage(const adit::wheel_odom_t& msg);

// LinK3D descriptor bins on FEATURES: int16 counts of 2 mm (to 65 m), a hundredth of the 0.2 m bin tolerance.
constexpr float kDescriptorScale = 0.002f;

// FEATURES: the four LOAM sets (rings; times only if not deskewed), FeatureSet::cloud as map_cloud (the
// caller thins it first), keypoints and descriptors. fromMessage gives cloud.points without rings.
adit::features_t toMessage(const FeatureSet& features);
FeatureSet fromMessage(const adit::features_t& msg);
// Only the LinK3D keypoints and descriptors (none when the descriptor's size or scale is not ours).
void keypointsOf(const adit::features_t& msg, std::vector<Eigen::Vector3f>& keypoints,
                 std::vector<LinK3dDescriptor>& descriptors);

// ODOM_SCAN / ODOM_MAPPED: features may be nullptr (GROUND_TRUTH): no points. Otherwise the message carries
// features->corner_less_sharp, surf_less_flat and cloud.points (whatever of them the caller left non-empty).
adit::odometry_t toMessage(const PoseEstimate& pose, const FeatureSet* features);
PoseEstimate fromMessage(const adit::odometry_t& msg);
// The points an odometry_t carries, as the FeatureSet fields they came from (corner_less_sharp,
// surf_less_flat, cloud with its deskewed flag).
FeatureSet featuresOf(const adit::odometry_t& msg);
// The pose alone: for monitoring copies (LAN relay, replay output).
void stripPoints(adit::odometry_t& msg);

adit::loop_closure_t toMessage(const LoopConstraint& loop, std::int64_t utime);
LoopConstraint fromMessage(const adit::loop_closure_t& msg);

}  // namespace adit::msg
