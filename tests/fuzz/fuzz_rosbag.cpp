// ROS 1 bags through the reader adit import rosbag uses: records, chunk decompression (none / bz2 / lz4),
// connections, then every message decoded both as a PointCloud2 and as an Imu.
#include "fuzz_input.hpp"
#include "io/ros_messages.hpp"
#include "io/rosbag.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  adit::fuzz::Input in(data, size);
  const std::string path = adit::fuzz::scratch().write("run.bag", in.rest());
  try {
    adit::io::BagReader reader(path);
    adit::io::BagMessage m;
    adit::io::PcdFolderConfig config;
    config.sensor = size % 2 ? "vlp16" : "unknown";
    config.num_beams = 16;
    while (reader.next(m)) {
      try {
        adit::io::decodePointCloud2(m.data.data(), m.data.size(), config, m.time_ns / 1000);
      } catch (const adit::io::ReadError&) {
      }
      try {
        adit::io::decodeImu(m.data.data(), m.data.size(), m.time_ns / 1000);
      } catch (const adit::io::ReadError&) {
      }
    }
  } catch (const adit::io::ReadError&) {
  }
  return 0;
}
