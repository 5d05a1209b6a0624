#include "sources/source_options.hpp"

#include "drivers/udp_lidar_source.hpp"
#include "runtime/process.hpp"
#include "sources/file_sources.hpp"
#include "sources/pcap_source.hpp"
#include "sources/rosbag_source.hpp"

namespace adit::sources {

void addLidarSourceOptions(CLI::App& app, LidarSourceArgs& a, bool kind_positional) {
  if (kind_positional) {
    app.add_option("kind", a.kind, "Data set kind: kitti | pcd | pcap | rosbag")
        ->required()->check(CLI::IsMember({"kitti", "pcd", "pcap", "rosbag"}));
    app.add_option("path", a.path, "KITTI sequence folder (sequences/NN), folder of PCD files, a .pcap/.pcapng capture or a ROS 1 bag file")
        ->required()->check(CLI::ExistingPath);
    app.add_option("--lidar-topic", a.lidar_topic, "rosbag: the sensor_msgs/PointCloud2 topic (required)");
    app.add_option("--imu-topic", a.imu_topic, "rosbag: a sensor_msgs/Imu topic to import as IMU");
  } else {
    app.add_option("--source", a.kind,
                   "kitti | pcd | pcap (recorded files) or vlp16 | rs16 | vlp32c | hdl32e (live sensor packets over UDP)")
        ->required()->check(CLI::IsMember({"kitti", "pcd", "pcap", "vlp16", "rs16", "vlp32c", "hdl32e"}));
    app.add_option("--path", a.path, "kitti/pcd/pcap: KITTI sequence folder (sequences/NN), folder of PCD files or a "
                   "capture file")->check(CLI::ExistingPath);
  }
  app.add_option("--driver-config", a.driver_configs, "pcap and live sensors: YAML with lidar_driver.* keys (launch/sensors/)");
  app.add_option("--port", a.port, "pcap and live sensors: UDP data port (default 2368, RS-16 6699)");
  app.add_option("--channel", a.channel, "Channel of the sweeps");
  app.add_option("--sensor", a.sensor, "pcap: the sensor that sent the packets (vlp16, rs16, vlp32c, hdl32e; default: --driver-config's "
                 "lidar_driver.model, else vlp16); PCD/rosbag: sensor "
                 "profile for rings by elevation (vlp16, rs16, hdl64)");
  app.add_option("--beams", a.beams, "KITTI: beams of the sensor that wrote the folder (default: detected from the "
                 "first scan); PCD/rosbag: beam count for a uniform fan when the profile is unknown")->check(CLI::Range(0, 255));
  app.add_option("--period", a.period_s, "PCD: sweep period (s) when file names are not timestamps; rosbag: sweep period");
}

bool isLiveSource(const LidarSourceArgs& a) {
  return a.kind == "vlp16" || a.kind == "rs16" || a.kind == "vlp32c" || a.kind == "hdl32e";
}

std::unique_ptr<runtime::MessageSource> makeLidarSource(const LidarSourceArgs& a) {
  if (isLiveSource(a)) {
    drivers::UdpLidarConfig config = drivers::udpLidarConfigFrom(runtime::loadConfig(a.driver_configs));
    config.model = a.kind;
    config.channel = a.channel;
    if (a.port > 0) config.port = a.port;
    return drivers::makeUdpLidarSource(config);
  }
  if (a.path.empty()) throw std::runtime_error("--path is required for a " + a.kind + " source");
  if (a.kind == "pcap") {
    drivers::UdpLidarConfig config = drivers::udpLidarConfigFrom(runtime::loadConfig(a.driver_configs));
    if (!a.sensor.empty()) config.model = a.sensor;  // else the driver config's (default vlp16)
    config.channel = a.channel;
    if (a.port > 0) config.port = a.port;
    return makePcapLidarSource(a.path, config);
  }
  if (a.kind == "kitti") return makeKittiSource(a.path, a.channel, a.beams);
  io::PcdFolderConfig cloud;
  if (!a.sensor.empty()) cloud.sensor = a.sensor;
  cloud.num_beams = a.beams;
  cloud.sweep_duration = a.period_s;
  if (a.kind == "pcd") return makePcdSource(a.path, cloud, a.channel);
  if (a.kind == "rosbag") {
    RosbagSourceConfig config;
    config.lidar_topic = a.lidar_topic;
    config.imu_topic = a.imu_topic;
    config.lidar_channel = a.channel;
    config.cloud = cloud;
    return makeRosbagSource(a.path, config);
  }
  throw std::runtime_error("unknown source kind '" + a.kind + "' (kitti, pcd, pcap or rosbag)");
}

}  // namespace adit::sources
