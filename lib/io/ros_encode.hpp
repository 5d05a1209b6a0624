// adit types serialised as ROS 1 message bodies (the inverse of ros_messages.hpp), for writing bags that ROS
// tools and adit's own reader both take: `adit sim --bag`, and the tests' bags.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "core/types.hpp"
#include "io/ros_messages.hpp"
#include "io/rosbag_writer.hpp"

namespace adit::io {

using RosBytes = std::vector<std::uint8_t>;

struct RosHeader {
  std::uint32_t seq = 0;
  RosStamp stamp;
  std::string frame_id;
};
RosStamp rosStampOf(std::int64_t utime);

// One sensor_msgs/PointField; datatype as PointField: 1 INT8, 2 UINT8, 3 INT16, 4 UINT16, 5 INT32, 6 UINT32,
// 7 FLOAT32, 8 FLOAT64.
struct RosPointField {
  std::string name;
  std::uint32_t offset = 0;
  std::uint8_t datatype = 7;
};

// sensor_msgs/PointCloud2, little-endian, `height` rows of `points.size() / point_step / height` points, each
// row followed by `row_padding` bytes (0xAB, so a reader that ignores row_step shows it).
RosBytes encodePointCloud2(const RosHeader& header, const std::vector<RosPointField>& fields, std::uint32_t point_step,
                           const std::vector<std::uint8_t>& points, std::uint32_t height = 1, std::uint32_t row_padding = 0);

// A sweep in the layout the ROS Velodyne driver (velodyne_pointcloud) publishes: x y z float32 at 0/4/8,
// intensity float32 at 16, ring uint16 at 20, time float32 at 24 (seconds, relative to the stamp), 32-byte
// points; the stamp is the sweep's last firing, so every time is <= 0.
RosBytes encodeVelodyneCloud(const LidarScan& scan, std::uint32_t seq, const std::string& frame_id);

// sensor_msgs/Imu; without an orientation, orientation_covariance[0] = -1 as the message documents.
RosBytes encodeImu(const RosHeader& header, const ImuSample& sample);

// The connection metadata of the two types (md5sums and definitions of ROS 1 Noetic's sensor_msgs).
const RosMessageType& pointCloud2Type();
const RosMessageType& imuType();

}  // namespace adit::io
