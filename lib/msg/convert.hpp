// Conversions between the plain stage types (core/types.hpp) and the LCM messages (lcmtypes/adit).
// The only place that knows both; stages never see LCM, processes never hand-copy fields.
#pragma once

#include "core/types.hpp"

#include <adit/features_t.hpp>
#include <adit/imu_t.hpp>
#include <adit/loop_closure_t.hpp>
#include <adit/odometry_t.hpp>
#include <adit/point_cloud_t.hpp>

namespace adit::msg {

adit::header_t makeHeader(std::int64_t utime, const std::string& frame_id);

adit::point_cloud_t toMessage(const LidarScan& scan);
LidarScan fromMessage(const adit::point_cloud_t& msg);
// A bare point set (feature subsets) with the sweep's metadata.
adit::point_cloud_t toMessage(const std::vector<LidarPoint>& points, const LidarScan& like);
std::vector<LidarPoint> pointsFromMessage(const adit::point_cloud_t& msg);

adit::imu_t toMessage(const ImuSample& imu);
ImuSample fromMessage(const adit::imu_t& msg);

adit::features_t toMessage(const FeatureSet& features);
FeatureSet fromMessage(const adit::features_t& msg);

// features may be empty (nullptr) when the receiver does not need them.
adit::odometry_t toMessage(const PoseEstimate& pose, const FeatureSet* features);
PoseEstimate fromMessage(const adit::odometry_t& msg);

adit::loop_closure_t toMessage(const LoopConstraint& loop, std::int64_t utime);
LoopConstraint fromMessage(const adit::loop_closure_t& msg);

}  // namespace adit::msg
