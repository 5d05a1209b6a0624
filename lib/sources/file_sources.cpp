#include "sources/file_sources.hpp"

#include "io/imu_csv.hpp"
#include "io/kitti.hpp"
#include "io/rings.hpp"
#include "msg/convert.hpp"
#include "msg/encode.hpp"
#include "msg/sweep_codec.hpp"

#include <spdlog/spdlog.h>

#include <functional>

namespace adit::sources {
namespace {

// Reads sweep i of n with `read`; skips (and counts) unreadable sweeps and sweeps whose time does not advance.
class ScanFileSource : public runtime::MessageSource {
 public:
  ScanFileSource(std::size_t count, std::function<LidarScan(std::size_t)> read, std::string channel)
      : count_(count), read_(std::move(read)), channel_(std::move(channel)) {}

  bool next(runtime::OutgoingMessage& out) override {
    while (index_ < count_) {
      const std::size_t i = index_++;
      LidarScan scan;
      try {
        scan = read_(i);
      } catch (const std::exception& e) {
        fail("read_error", e.what(), true);
        continue;
      }
      if (last_utime_ >= 0 && scan.utime <= last_utime_) {
        fail("time_backwards", "sweep " + std::to_string(i) + " at utime " + std::to_string(scan.utime) +
                                   " is not after " + std::to_string(last_utime_), false);
        continue;
      }
      if (scan.points.empty()) health_.counters["empty_scan"] += 1;  // published: downstream flags it
      last_utime_ = scan.utime;
      scan.seq = seq_++;
      // No firing table for recorded files: the compact per-point layout.
      adit::lidar_scan_t m = msg::encodeSweep(scan, nullptr);
      out = {channel_, msg::encode(m), scan.utime};
      ++health_.outputs;
      return true;
    }
    return false;
  }
  const runtime::Health& health() const override { return health_; }

 private:
  void fail(const std::string& counter, const std::string& what, bool error) {
    (error ? health_.errors : health_.drops) += 1;
    health_.counters[counter] += 1;
    health_.last_error = what;
    spdlog::error("{}: skipped", what);
  }
  std::size_t count_, index_ = 0;
  std::function<LidarScan(std::size_t)> read_;
  std::string channel_;
  std::int64_t last_utime_ = -1, seq_ = 0;
  runtime::Health health_;
};

class ImuSource : public runtime::MessageSource {
 public:
  ImuSource(io::ImuCsvResult data, std::string channel, const std::string& path)
      : data_(std::move(data)), channel_(std::move(channel)) {
    health_.errors = static_cast<std::int64_t>(data_.bad_lines.size());
    if (!data_.bad_lines.empty()) {
      health_.counters["bad_line"] = health_.errors;
      health_.last_error = "IMU file '" + path + "': " + data_.badLineSummary();
      spdlog::error("{}", health_.last_error);
    }
  }
  bool next(runtime::OutgoingMessage& out) override {
    while (index_ < data_.samples.size()) {
      const ImuSample& s = data_.samples[index_++];
      if (last_utime_ >= 0 && s.utime <= last_utime_) {
        ++health_.drops;
        health_.counters["time_backwards"] += 1;
        continue;
      }
      last_utime_ = s.utime;
      adit::imu_t m = msg::toMessage(s);
      m.header.seq = seq_++;
      out = {channel_, msg::encode(m), s.utime};
      ++health_.outputs;
      return true;
    }
    return false;
  }
  const runtime::Health& health() const override { return health_; }

 private:
  io::ImuCsvResult data_;
  std::string channel_;
  std::size_t index_ = 0;
  std::int64_t last_utime_ = -1, seq_ = 0;
  runtime::Health health_;
};

}  // namespace

std::unique_ptr<runtime::MessageSource> makeKittiSource(const std::string& sequence_dir, const std::string& channel,
                                                        int num_beams) {
  auto sequence = std::make_shared<io::KittiSequence>(sequence_dir);
  if (num_beams == 0 && sequence->size() > 0) {
    // Detected from the first scan; if that cannot be read or shows no clear fan, KITTI's own 64 (the reading
    // of each scan reports a bad file in its turn).
    const std::string& first = sequence->scanFiles().front();
    try {
      num_beams = io::detectBeamCount(io::readKittiBin(first));
    } catch (const io::ReadError&) {
      num_beams = 0;
    }
    if (num_beams == 0) {
      num_beams = io::kKittiNumBeams;
      spdlog::warn("KITTI: the beam count does not show in '{}': {} assumed (--beams N sets it)", first, num_beams);
    } else {
      spdlog::info("KITTI: {} beams (detected from the first scan; --beams N sets it)", num_beams);
    }
  }
  if (num_beams > 0) sequence->setNumBeams(num_beams);
  return std::make_unique<ScanFileSource>(sequence->size(), [sequence](std::size_t i) { return sequence->scan(i); },
                                          channel);
}

std::unique_ptr<runtime::MessageSource> makePcdSource(const std::string& folder, const io::PcdFolderConfig& config,
                                                      const std::string& channel) {
  auto pcd = std::make_shared<io::PcdFolder>(folder, config);
  return std::make_unique<ScanFileSource>(pcd->size(), [pcd](std::size_t i) { return pcd->scan(i); }, channel);
}

std::unique_ptr<runtime::MessageSource> makeImuCsvSource(const std::string& path, const std::string& channel) {
  return std::make_unique<ImuSource>(io::readImuCsv(path), channel, path);
}

}  // namespace adit::sources
