// Writes the seed corpus of the rosbag harness: small bags (no header padding) with one chunk of each
// compression holding a Velodyne-layout and an Ouster-layout sweep and two IMU samples, and one
// unindexed bag. Run from the repository root: build/bin/fuzz_make_rosbag_seeds tests/fuzz/corpus/rosbag
#include <fstream>
#include <iostream>

#include "bag_writer.hpp"
#include "clouds.hpp"

int main(int argc, char** argv) {
  if (argc != 2) {
    std::cerr << "usage: fuzz_make_rosbag_seeds <corpus dir>\n";
    return 2;
  }
  using namespace adit::test;
  for (const char* compression : {"none", "bz2", "lz4"}) {
    BagWriter w(compression, 0);
    w.addConnection(0, "/points", "sensor_msgs/PointCloud2");
    w.addConnection(1, "/imu", "sensor_msgs/Imu");
    w.addMessage(0, 1000000000, velodyneCloud(1, 0, 2, 1).message);
    adit::ImuSample s;
    s.orientation = Eigen::Quaterniond::Identity();
    w.addMessage(1, 1000000000, imuMessage(1, 0, s));
    w.endChunk();
    w.addMessage(0, 1100000000, ousterCloud(1, 100000000, 2, 2).message);
    w.addMessage(1, 1100000000, imuMessage(1, 100000000, adit::ImuSample{}));
    std::ofstream(std::string(argv[1]) + "/bag_" + compression, std::ios::binary) << w.finish();
  }
  return 0;
}
