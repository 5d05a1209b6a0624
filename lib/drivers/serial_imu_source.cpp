#include "drivers/serial_imu_source.hpp"

#include "drivers/fdilink.hpp"
#include "drivers/serial_port.hpp"
#include "msg/convert.hpp"
#include "msg/encode.hpp"
#include "runtime/process.hpp"

#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include <chrono>
#include <cmath>
#include <deque>
#include <stdexcept>
#include <thread>

namespace adit::drivers {
namespace {

constexpr std::size_t kN100FrameBytes = 8 + kFdiImuPayloadBytes;
constexpr std::size_t kMaxTextLine = 512;

class SerialImuSource : public runtime::MessageSource {
 public:
  SerialImuSource(const SerialImuConfig& config, std::function<bool()> stop, std::function<std::int64_t()> host_clock)
      : config_(config), stop_(std::move(stop)), host_clock_(std::move(host_clock)), sync_(syncConfig(config)) {
    if (!host_clock_) host_clock_ = runtime::wallUtime;
  }

  bool next(runtime::OutgoingMessage& out) override {
    while (pending_.empty()) {
      if (runtime::stopRequested() || (stop_ && stop_())) return false;
      if (!port_.isOpen() && !reopen()) continue;
      std::uint8_t buffer[1024];
      std::size_t got = 0;
      switch (port_.read(buffer, sizeof buffer, 100, got)) {
        case SerialPort::Read::Data: feed(buffer, got, host_clock_()); break;
        case SerialPort::Read::Timeout: idle(); break;
        case SerialPort::Read::Lost:
          count("device_lost", config_.device + " disappeared (unplugged?); reopening every " +
                                   fmt::format("{}", config_.reopen_period_s) + " s");
          health_.counters["waiting_for_device"] = 1;
          break;
      }
    }
    const ImuSample sample = pending_.front();
    pending_.pop_front();
    adit::imu_t m = msg::toMessage(sample);
    m.header.seq = seq_++;
    out.channel = config_.channel;
    out.data = msg::encode(m);
    out.utime = sample.utime;
    ++health_.outputs;
    return true;
  }

  const runtime::Health& health() const override {
    for (const auto& [name, value] : parser_.counters()) health_.counters[name] = value;
    health_.counters["clock_jumps"] = sync_.clockJumps();
    return health_;
  }

 private:
  static ClockSyncConfig syncConfig(const SerialImuConfig& c) {
    ClockSyncConfig s = c.sync;
    // 10 bits a byte on the wire (start, 8 data, stop).
    s.transport_delay_s = c.transport_delay_s >= 0 ? c.transport_delay_s : kN100FrameBytes * 10.0 / c.baud;
    return s;
  }

  // Opens the device, or waits (calling idle) until the next attempt is due; true once it is open.
  bool reopen() {
    const auto now = std::chrono::steady_clock::now();
    if (attempts_ > 0 && now - last_attempt_ < std::chrono::duration<double>(config_.reopen_period_s)) {
      std::this_thread::sleep_for(std::chrono::milliseconds(100));
      idle();
      return false;
    }
    last_attempt_ = now;
    std::string error;
    const bool first = attempts_++ == 0;
    if (!port_.open(config_.device, config_.baud, error)) {
      if (first || attempts_ % 30 == 0) spdlog::warn("{} (waiting for it)", error);
      health_.last_error = error;
      health_.counters["waiting_for_device"] = 1;
      return false;
    }
    if (!first && health_.counters["device_lost"] > 0) health_.counters["reopened"] += 1;
    spdlog::info("reading {} ({} protocol, {} baud)", config_.device, config_.protocol, config_.baud);
    health_.counters["waiting_for_device"] = 0;
    parser_ = FdiLinkParser();  // bytes of a frame cut by the unplug never complete
    line_.clear();
    return true;
  }

  void count(const std::string& counter, const std::string& message) {
    ++health_.errors;
    health_.counters[counter] += 1;
    health_.last_error = message;
    spdlog::error("{}", message);
  }

  void feed(const std::uint8_t* data, std::size_t size, std::int64_t host_us) {
    if (config_.protocol == "text") return feedText(data, size, host_us);
    parser_.push(data, size, [&](const FdiFrame& frame) { onFrame(frame, host_us); });
  }

  void onFrame(const FdiFrame& frame, std::int64_t host_us) {
    if (frame.type == kFdiAhrsPacket) {
      if (auto ahrs = decodeFdiAhrs(frame.payload)) last_ahrs_ = ahrs;
      else health_.counters["bad_packet"] += 1;
      return;
    }
    if (frame.type != kFdiImuPacket) {
      health_.counters["other_packet"] += 1;  // e.g. INS or GNSS packets the device was set to send
      return;
    }
    const auto imu = decodeFdiImu(frame.payload);
    if (!imu) {
      health_.counters["bad_packet"] += 1;
      return;
    }
    ImuSample s;
    s.gyro = imu->gyro;
    s.accel = imu->accel;
    if (last_ahrs_ && std::llabs(last_ahrs_->device_us - imu->device_us) <= config_.max_ahrs_age_s * 1e6)
      s.orientation = last_ahrs_->orientation;
    // The N100's magnetometer fields are left out: their unit is not documented in the sources we found.
    s.utime = stampOf(imu->device_us, host_us);
    pending_.push_back(s);
  }

  void feedText(const std::uint8_t* data, std::size_t size, std::int64_t host_us) {
    for (std::size_t i = 0; i < size; ++i) {
      const char c = static_cast<char>(data[i]);
      if (c != '\n') {
        if (line_.size() < kMaxTextLine) line_.push_back(c);
        else overlong_ = true;
        continue;
      }
      if (!line_.empty() && line_.back() == '\r') line_.pop_back();
      if (overlong_) health_.counters["bad_line"] += 1;
      else if (!line_.empty() && line_[0] != '#') parseLine(host_us);
      line_.clear();
      overlong_ = false;
    }
  }

  void parseLine(std::int64_t host_us) {
    ImuSample s;
    std::string reason;
    if (!io::parseImuCsvLine(line_, config_.text, s, reason)) {
      health_.counters["bad_line"] += 1;
      health_.last_error = "IMU line '" + line_.substr(0, 60) + "': " + reason;
      return;
    }
    s.utime = stampOf(s.utime, host_us);
    pending_.push_back(s);
  }

  std::int64_t stampOf(std::int64_t device_us, std::int64_t host_us) {
    if (config_.clock == "host") return host_us;
    return sync_.stamp(device_us, host_us);
  }

  SerialImuConfig config_;
  std::function<bool()> stop_;
  std::function<std::int64_t()> host_clock_;
  DeviceClockSync sync_;
  SerialPort port_;
  FdiLinkParser parser_;
  std::optional<FdiAhrs> last_ahrs_;
  std::string line_;
  bool overlong_ = false;
  std::deque<ImuSample> pending_;
  std::int64_t seq_ = 0;
  int attempts_ = 0;
  std::chrono::steady_clock::time_point last_attempt_;
  mutable runtime::Health health_;
};

}  // namespace

std::unique_ptr<runtime::MessageSource> makeSerialImuSource(const SerialImuConfig& config, std::function<bool()> stop,
                                                            std::function<std::int64_t()> host_clock) {
  if (config.protocol != "n100" && config.protocol != "text")
    throw std::invalid_argument("--protocol must be n100 or text, not '" + config.protocol + "'");
  if (config.clock != "sync" && config.clock != "host")
    throw std::invalid_argument("--clock must be sync or host, not '" + config.clock + "'");
  if (!SerialPort::supportedBaud(config.baud))
    throw std::invalid_argument("baud rate " + std::to_string(config.baud) + " is not supported");
  return std::make_unique<SerialImuSource>(config, std::move(stop), std::move(host_clock));
}

}  // namespace adit::drivers
