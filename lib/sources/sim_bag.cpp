#include "sources/sim_bag.hpp"

#include "io/ros_encode.hpp"

namespace adit::sources {
namespace {

constexpr std::uint32_t kLidarConnection = 0, kImuConnection = 1;

io::RosbagWriter::Options bagOptions(const std::string& compression) {
  io::RosbagWriter::Options options;
  options.compression = compression;
  return options;
}

}  // namespace

SimBagRecorder::SimBagRecorder(std::ostream& out, const std::string& compression, SimBagTopics topics)
    : writer_(out, bagOptions(compression)) {
  writer_.addConnection(kLidarConnection, topics.lidar, io::pointCloud2Type());
  writer_.addConnection(kImuConnection, topics.imu, io::imuType());
}

void SimBagRecorder::addSweep(const LidarScan& scan) {
  writer_.write(kLidarConnection, scan.utime * 1000, io::encodeVelodyneCloud(scan, sweep_seq_++, "velodyne"));
}

void SimBagRecorder::addImu(const ImuSample& sample) {
  writer_.write(kImuConnection, sample.utime * 1000, io::encodeImu({imu_seq_++, io::rosStampOf(sample.utime), "imu"}, sample));
}

}  // namespace adit::sources
