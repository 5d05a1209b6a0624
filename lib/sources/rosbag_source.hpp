// A ROS 1 bag as a message source: the PointCloud2 messages of one topic become LIDAR_POINTS sweeps and
// (optionally) the Imu messages of another become IMU samples, merged in sensor-time order. Shared by
// `adit import rosbag` and any bridge that wants to replay a bag.
//
// Damage is counted, logged and skipped, and the rest of the bag still flows (health().drops):
//   bag_chunk_lost   a chunk that does not decompress or holds malformed records (io/rosbag.hpp)
//   bag_truncated    the file ends inside a record
//   decode_error     a message that does not decode (short, field outside the point, unknown datatype)
//   time_backwards   a message not after the previous one of its channel (after the 1 s reordering below)
// Stamps: a message's own header stamp (ros_messages.hpp says how sweep times are derived), so a sweep
// stamped at its start lands after the IMU samples recorded during it; messages are held in a 1 s window
// and released in stamp order, which keeps LIDAR and IMU interleaved as a live run would.
#pragma once

#include "io/pcd.hpp"
#include "runtime/source.hpp"

#include <memory>
#include <string>

namespace adit::sources {

struct RosbagSourceConfig {
  std::string lidar_topic;   // required: a sensor_msgs/PointCloud2 topic
  std::string imu_topic;     // optional: a sensor_msgs/Imu topic
  std::string lidar_channel = "LIDAR_POINTS";
  std::string imu_channel = "IMU";
  io::PcdFolderConfig cloud;  // sensor profile for clouds without a ring field; sweep_duration
};

// Throws std::runtime_error (one line) if the file is not a bag, or if its index lists the topics and
// a requested one is missing or of another type (the message names the topics the bag has).
std::unique_ptr<runtime::MessageSource> makeRosbagSource(const std::string& path, const RosbagSourceConfig& config);

}  // namespace adit::sources
