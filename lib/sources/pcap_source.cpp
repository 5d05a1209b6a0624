#include "sources/pcap_source.hpp"

#include "io/io_error.hpp"
#include "msg/encode.hpp"
#include "msg/sweep_codec.hpp"
#include "sources/capture_lidar_reader.hpp"

#include <spdlog/spdlog.h>

#include <deque>
#include <filesystem>
#include <fstream>

namespace adit::sources {
namespace {

std::unique_ptr<std::ifstream> openCapture(const std::string& path) {
  auto in = std::make_unique<std::ifstream>(path, std::ios::binary);
  if (!*in) throw io::ReadError("capture '" + path + "': cannot open it");
  return in;
}

class PcapLidarSource : public runtime::MessageSource {
 public:
  PcapLidarSource(const std::string& path, const drivers::UdpLidarConfig& config)
      : file_(openCapture(path)), reader_(*file_, path, config), channel_(config.channel) {
    std::error_code error;
    const auto size = std::filesystem::file_size(path, error);
    file_size_ = error ? 0.0 : static_cast<double>(size);
  }

  bool next(runtime::OutgoingMessage& out) override {
    while (ready_.empty()) {
      if (!reader_.read(sweeps_)) {
        if (!summarised_) {
          summarised_ = true;
          spdlog::info("{}", reader_.summary());
        }
        return false;
      }
      for (LidarScan& s : sweeps_) ready_.push_back(std::move(s));
      sweeps_.clear();
    }
    LidarScan& scan = ready_.front();
    out.channel = channel_;
    out.data = msg::encode(msg::encodeSweep(scan, &reader_.firingTable()));
    out.utime = scan.utime;
    ready_.pop_front();
    return true;
  }

  const runtime::Health& health() const override {
    health_ = reader_.health();
    return health_;
  }

  double progress() const override {
    if (file_size_ <= 0) return -1.0;
    const auto at = file_->tellg();
    return at < 0 ? 1.0 : static_cast<double>(at) / file_size_;
  }

 private:
  std::unique_ptr<std::ifstream> file_;
  CaptureLidarReader reader_;
  std::string channel_;
  double file_size_ = 0;
  bool summarised_ = false;
  std::vector<LidarScan> sweeps_;
  std::deque<LidarScan> ready_;
  mutable runtime::Health health_;
};

}  // namespace

std::unique_ptr<runtime::MessageSource> makePcapLidarSource(const std::string& path,
                                                            const drivers::UdpLidarConfig& config) {
  return std::make_unique<PcapLidarSource>(path, config);
}

}  // namespace adit::sources
