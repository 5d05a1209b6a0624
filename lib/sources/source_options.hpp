// Command-line options of a lidar data source, shared by adit-lidar-bridge and `adit import`.
#pragma once

#include "runtime/source.hpp"

#include <CLI/CLI.hpp>

#include <memory>
#include <string>

namespace adit::sources {

struct LidarSourceArgs {
  std::string kind;   // "kitti", "pcd", "pcap", "rosbag" (recorded) or "vlp16", "rs16", "vlp32c", "hdl32e" (live UDP packets)
  std::string path;   // sequence folder, PCD folder, capture file or bag file
  std::vector<std::string> driver_configs;  // live and pcap: YAML with lidar_driver.* keys
  int port = 0;                              // live and pcap: UDP port (0 = the sensor's default)
  std::string channel = "LIDAR_POINTS";
  // pcap: the sensor model; PCD: sensor profile for rings by elevation when the files have no ring field.
  // Empty: the --driver-config file's lidar_driver.model (pcap), vlp16 when neither names one.
  std::string sensor;
  int beams = 0;              // KITTI: the sensor's (0 = detected); PCD: 0 = the profile's
  double period_s = 0.1;      // sweep period when file names are not timestamps
  // ROS bag only (import): the PointCloud2 topic, and the Imu topic imported alongside (optional).
  std::string lidar_topic, imu_topic;
};

// kind_positional: `adit import kitti <dir>` takes the kind as a positional; the bridge uses --source.
void addLidarSourceOptions(CLI::App& app, LidarSourceArgs& args, bool kind_positional);
bool isLiveSource(const LidarSourceArgs& args);
// Throws std::runtime_error (unknown kind, unreadable folder, socket that cannot be bound).
std::unique_ptr<runtime::MessageSource> makeLidarSource(const LidarSourceArgs& args);

}  // namespace adit::sources
