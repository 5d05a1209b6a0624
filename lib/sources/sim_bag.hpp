// A simulated run as the ROS 1 bag a robot running the ROS Velodyne and IMU drivers would have recorded
// (`adit sim --bag`): each sweep a sensor_msgs/PointCloud2 on /velodyne_points in velodyne_pointcloud's
// layout (io/ros_encode.hpp; stamped at its last firing, per-point times <= 0), each IMU sample a
// sensor_msgs/Imu on /imu/data, record time = header stamp, in publishing order.
#pragma once

#include "core/types.hpp"
#include "io/rosbag_writer.hpp"

#include <ostream>
#include <string>

namespace adit::sources {

struct SimBagTopics {
  std::string lidar = "/velodyne_points";
  std::string imu = "/imu/data";
};

class SimBagRecorder {
 public:
  SimBagRecorder(std::ostream& out, const std::string& compression, SimBagTopics topics = {});
  void addSweep(const LidarScan& scan);
  void addImu(const ImuSample& sample);
  // Writes the bag's index; the stream then holds the whole bag.
  void finish() { writer_.finish(); }
  std::int64_t messages() const { return writer_.messages(); }

 private:
  io::RosbagWriter writer_;
  std::uint32_t sweep_seq_ = 0, imu_seq_ = 0;
};

}  // namespace adit::sources
