#include "sources/rosbag_source.hpp"

#include "io/ros_messages.hpp"
#include "io/rosbag.hpp"
#include "msg/convert.hpp"
#include "msg/encode.hpp"
#include "msg/sweep_codec.hpp"

#include <spdlog/spdlog.h>

#include <limits>
#include <map>

namespace adit::sources {
namespace {

constexpr std::int64_t kReorderWindowUs = 1000000;
constexpr char kCloudType[] = "sensor_msgs/PointCloud2";
constexpr char kImuType[] = "sensor_msgs/Imu";

class RosbagSource : public runtime::MessageSource {
 public:
  RosbagSource(const std::string& path, RosbagSourceConfig config) : reader_(path), config_(std::move(config)) {
    checkTopic(config_.lidar_topic, kCloudType);
    if (!config_.imu_topic.empty()) checkTopic(config_.imu_topic, kImuType);
  }

  bool next(runtime::OutgoingMessage& out) override {
    for (;;) {
      while (!reader_done_ && (window_.empty() || window_.rbegin()->first.first - window_.begin()->first.first < kReorderWindowUs))
        readOne();
      if (window_.empty()) return false;
      out = std::move(window_.begin()->second);
      window_.erase(window_.begin());
      std::int64_t& last = last_utime_.try_emplace(out.channel, std::numeric_limits<std::int64_t>::min()).first->second;
      if (out.utime <= last) {
        drop("time_backwards", out.channel + " message at utime " + std::to_string(out.utime) + " is not after " + std::to_string(last));
        continue;
      }
      last = out.utime;
      ++health_.outputs;
      return true;
    }
  }
  const runtime::Health& health() const override { return health_; }
  double progress() const override { return reader_.progress(); }

 private:
  // An indexed bag lists its connections up front: a wrong topic is an error before anything is read.
  void checkTopic(const std::string& topic, const char* type) const {
    if (reader_.connections().empty()) return;  // unindexed: found out while reading
    std::string listing;
    for (const auto& [id, c] : reader_.connections()) {
      if (c.topic == topic && c.type == type) return;
      if (c.topic == topic)
        throw io::ReadError("bag '" + reader_.path() + "': topic " + topic + " is " + c.type + ", not " + type);
      listing += (listing.empty() ? "" : ", ") + c.topic + " (" + c.type + ")";
    }
    throw io::ReadError("bag '" + reader_.path() + "' has no topic " + topic + "; it has " + listing);
  }

  void readOne() {
    io::BagMessage m;
    if (!reader_.next(m)) {
      reader_done_ = true;
      reportDamage();
      return;
    }
    reportDamage();
    const io::BagConnection& c = reader_.connections().at(m.conn);
    const std::int64_t record_utime = m.time_ns / 1000;
    try {
      if (c.topic == config_.lidar_topic && c.type == kCloudType) {
        LidarScan scan = io::decodePointCloud2(m.data.data(), m.data.size(), config_.cloud, record_utime);
        scan.seq = lidar_seq_++;
        scan.sensor = config_.cloud.sensor;
        scan.sweep_duration = static_cast<float>(config_.cloud.sweep_duration);
        push({config_.lidar_channel, msg::encode(msg::encodeSweep(scan, nullptr)), scan.utime});
      } else if (!config_.imu_topic.empty() && c.topic == config_.imu_topic && c.type == kImuType) {
        const ImuSample s = io::decodeImu(m.data.data(), m.data.size(), record_utime);
        adit::imu_t msg = msg::toMessage(s);
        msg.header.seq = imu_seq_++;
        push({config_.imu_channel, msg::encode(msg), s.utime});
      }
    } catch (const io::ReadError& e) {
      drop("decode_error", c.topic + " message at bag time " + std::to_string(record_utime) + " us: " + e.what());
    }
  }

  void push(runtime::OutgoingMessage m) {
    const std::int64_t utime = m.utime;
    window_.emplace(std::make_pair(utime, order_++), std::move(m));
  }

  // New chunk losses or a truncation since the last look: counted once each, one log line each.
  void reportDamage() {
    const io::BagReadStats& s = reader_.stats();
    while (chunks_lost_seen_ < s.chunks_lost) {
      ++chunks_lost_seen_;
      drop("bag_chunk_lost", s.last_error);
    }
    if (s.truncated && !truncation_seen_) {
      truncation_seen_ = true;
      drop("bag_truncated", s.last_error);
    }
  }

  void drop(const std::string& counter, const std::string& what) {
    ++health_.drops;
    health_.counters[counter] += 1;
    health_.last_error = what;
    spdlog::error("{}: skipped", what);
  }

  io::BagReader reader_;
  RosbagSourceConfig config_;
  std::map<std::pair<std::int64_t, std::int64_t>, runtime::OutgoingMessage> window_;  // (utime, arrival) -> message
  std::map<std::string, std::int64_t> last_utime_;
  std::int64_t order_ = 0, lidar_seq_ = 0, imu_seq_ = 0, chunks_lost_seen_ = 0;
  bool reader_done_ = false, truncation_seen_ = false;
  runtime::Health health_;
};

}  // namespace

std::unique_ptr<runtime::MessageSource> makeRosbagSource(const std::string& path, const RosbagSourceConfig& config) {
  if (config.lidar_topic.empty()) throw std::runtime_error("a bag import needs --lidar-topic");
  return std::make_unique<RosbagSource>(path, config);
}

}  // namespace adit::sources
