#include "msg/type_name.hpp"

#include <adit/features_t.hpp>
#include <adit/imu_t.hpp>
#include <adit/wheel_odom_t.hpp>
#include <adit/lidar_scan_t.hpp>
#include <adit/loop_closure_t.hpp>
#include <adit/map_update_t.hpp>
#include <adit/odometry_t.hpp>
#include <adit/odometry_v1_t.hpp>
#include <adit/point_cloud_t.hpp>
#include <adit/pose_graph_t.hpp>
#include <adit/status_t.hpp>

namespace adit::msg {
namespace {

template <class Msg>
bool hasHash(std::int64_t hash) {
  return hash == Msg::getHash();
}

}  // namespace

std::string messageTypeName(const std::uint8_t* data, std::size_t size) {
  if (size < 8) return "";
  std::int64_t hash = 0;
  for (int i = 0; i < 8; ++i) hash = static_cast<std::int64_t>((static_cast<std::uint64_t>(hash) << 8) | data[i]);
  if (hasHash<adit::lidar_scan_t>(hash)) return "lidar_scan_t";
  if (hasHash<adit::point_cloud_t>(hash)) return "point_cloud_t";
  if (hasHash<adit::imu_t>(hash)) return "imu_t";
  if (hasHash<adit::wheel_odom_t>(hash)) return "wheel_odom_t";
  if (hasHash<adit::features_t>(hash)) return "features_t";
  if (hasHash<adit::odometry_t>(hash)) return "odometry_t";
  if (hasHash<adit::odometry_v1_t>(hash)) return "odometry_v1_t";  // logs before session 31
  if (hasHash<adit::loop_closure_t>(hash)) return "loop_closure_t";
  if (hasHash<adit::pose_graph_t>(hash)) return "pose_graph_t";
  if (hasHash<adit::map_update_t>(hash)) return "map_update_t";
  if (hasHash<adit::status_t>(hash)) return "status_t";
  return "";
}

}  // namespace adit::msg
