#include "drivers/udp_lidar_source.hpp"

#include "drivers/rs16_decoder.hpp"
#include "drivers/udp_receiver.hpp"
#include "drivers/vlp16_decoder.hpp"
#include "msg/convert.hpp"
#include "msg/encode.hpp"
#include "msg/sweep_codec.hpp"
#include "runtime/process.hpp"

#include <spdlog/spdlog.h>

#include <chrono>
#include <cmath>
#include <deque>
#include <optional>
#include <stdexcept>

namespace adit::drivers {
namespace {

class UdpLidarSource : public runtime::MessageSource {
 public:
  UdpLidarSource(const UdpLidarConfig& config, std::function<bool()> stop)
      : stream_(streamConfigOf(config)),
        socket_(config.bind_address, dataPortOf(config), config.recv_buffer_bytes),
        channel_(config.channel),
        idle_timeout_(std::chrono::duration<double>(config.idle_timeout_s)),
        stop_(std::move(stop)) {
    openDeviceInfoPort(config);
    spdlog::info("{} listening on {}:{} (receive buffer {} bytes{})", config.model, config.bind_address,
                 socket_.port(), socket_.receiveBufferBytes(),
                 socket_.receiveBufferBytes() < config.recv_buffer_bytes
                     ? "; raise net.core.rmem_max for " + std::to_string(config.recv_buffer_bytes)
                     : std::string());
  }

  bool next(runtime::OutgoingMessage& out) override {
    using Clock = std::chrono::steady_clock;
    auto last_packet = Clock::now();
    while (ready_.empty()) {
      if (runtime::stopRequested() || (stop_ && stop_())) return false;
      std::size_t size = 0;
      std::int64_t receive_ns = 0;
      std::string error;
      switch (socket_.receive(payload_, size, receive_ns, 100, error)) {
        case UdpReceiver::Result::kPacket:
          last_packet = Clock::now();
          if (packets_++ % 256 == 0) readDeviceInfo();  // before the first packet, then every ~0.3 s
          stream_.push(payload_.data(), size, receive_ns, sweeps_);
          for (LidarScan& s : sweeps_) ready_.push_back(std::move(s));
          sweeps_.clear();
          break;
        case UdpReceiver::Result::kTimeout:
          readDeviceInfo();
          if (idle_timeout_.count() > 0 && Clock::now() - last_packet > idle_timeout_) {
            spdlog::info("no lidar packet for {} s: stopping", idle_timeout_.count());
            return false;
          }
          idle();
          break;
        case UdpReceiver::Result::kError:
          receive_errors_ += 1;
          if (receive_errors_ == 1 || receive_errors_ % 1000 == 0) spdlog::error("{}", error);
          last_error_ = error;
          break;
      }
    }
    LidarScan& scan = ready_.front();
    adit::lidar_scan_t m = msg::encodeSweep(scan, &stream_.firingTable());
    out.channel = channel_;
    out.data = msg::encode(m);
    out.utime = scan.utime;
    ready_.pop_front();
    return true;
  }

  const runtime::Health& health() const override {
    health_ = stream_.health();
    if (receive_errors_ > 0) {
      health_.errors += receive_errors_;
      health_.counters["receive_error"] = receive_errors_;
      health_.last_error = last_error_;
    }
    return health_;
  }

 private:
  // RS-16: the sensor sends its DIFOP packet (return mode, calibrated vertical angles) once a second to its
  // own port. A port someone else holds costs only the calibration: the nominal table is used, with a warning.
  void openDeviceInfoPort(const UdpLidarConfig& config) {
    if (config.model != "rs16" || config.difop_port < 0) return;
    const auto port = static_cast<std::uint16_t>(config.difop_port > 0 ? config.difop_port : kRs16DifopPort);
    try {
      device_info_.emplace(config.bind_address, port, 64 * 1024);
      spdlog::info("rs16 DIFOP listening on {}:{}", config.bind_address, port);
    } catch (const std::runtime_error& e) {
      spdlog::warn("no RS-16 DIFOP: {}; return mode and vertical angles stay as configured", e.what());
    }
  }
  // Hands every DIFOP datagram waiting to the stream (it comes 1 Hz; read before the first data packet,
  // every 256 packets and when idle, so a socket read per packet is not spent on it).
  void readDeviceInfo() {
    if (!device_info_) return;
    std::size_t size = 0;
    std::int64_t receive_ns = 0;
    std::string error;
    while (device_info_->receive(difop_payload_, size, receive_ns, 0, error) == UdpReceiver::Result::kPacket)
      stream_.pushDeviceInfo(difop_payload_.data(), std::min(size, difop_payload_.size()));
  }

  LidarPacketStream stream_;
  UdpReceiver socket_;
  std::optional<UdpReceiver> device_info_;
  std::vector<std::uint8_t> difop_payload_;
  std::int64_t packets_ = 0;
  std::string channel_;
  std::chrono::duration<double> idle_timeout_;
  std::function<bool()> stop_;
  std::vector<std::uint8_t> payload_;
  std::vector<LidarScan> sweeps_;
  std::deque<LidarScan> ready_;
  std::int64_t receive_errors_ = 0;
  std::string last_error_;
  mutable runtime::Health health_;
};

LidarModel modelOf(const std::string& name) {
  if (name == "vlp16") return LidarModel::kVlp16;
  if (name == "rs16") return LidarModel::kRs16;
  if (name == "vlp32c") return LidarModel::kVlp32c;
  if (name == "hdl32e") return LidarModel::kHdl32e;
  throw std::invalid_argument("lidar driver: unknown model '" + name + "' (vlp16, rs16, vlp32c or hdl32e)");
}

}  // namespace

UdpLidarConfig udpLidarConfigFrom(const Config& c) {
  UdpLidarConfig d;
  const std::string k = "lidar_driver.";
  d.model = c.get(k + "model", d.model);
  d.bind_address = c.get(k + "bind_address", d.bind_address);
  d.port = c.get(k + "port", d.port);
  d.recv_buffer_bytes = c.get(k + "recv_buffer_bytes", d.recv_buffer_bytes);
  d.channel = c.get(k + "channel", d.channel);
  d.sensor_name = c.get(k + "sensor_name", d.sensor_name);
  d.time_source = c.get(k + "time_source", d.time_source);
  d.max_clock_jump_s = c.get(k + "max_clock_jump_s", d.max_clock_jump_s);
  d.transport_delay_s = c.get(k + "transport_delay_s", d.transport_delay_s);
  d.cut_azimuth_deg = c.get(k + "cut_azimuth_deg", d.cut_azimuth_deg);
  d.max_sweep_duration_s = c.get(k + "max_sweep_duration_s", d.max_sweep_duration_s);
  d.max_firing_gap_s = c.get(k + "max_firing_gap_s", d.max_firing_gap_s);
  d.vertical_angles_deg = c.getList<double>(k + "vertical_angles_deg", d.vertical_angles_deg);
  d.idle_timeout_s = c.get(k + "idle_timeout_s", d.idle_timeout_s);
  d.sensor_address = c.get(k + "sensor_address", d.sensor_address);
  d.accept_product_ids = c.getList<int>(k + "accept_product_ids", d.accept_product_ids);
  d.dual_return = c.get(k + "dual_return", d.dual_return);
  d.difop_port = c.get(k + "difop_port", d.difop_port);
  return d;
}

std::uint16_t dataPortOf(const UdpLidarConfig& config) {
  if (config.port < 0 || config.port > 65535)
    throw std::invalid_argument("lidar driver: port " + std::to_string(config.port) + " is not a UDP port");
  if (config.port > 0) return static_cast<std::uint16_t>(config.port);
  return modelOf(config.model) == LidarModel::kRs16 ? kRs16DefaultPort : kVlp16DefaultPort;
}

LidarStreamConfig streamConfigOf(const UdpLidarConfig& config) {
  LidarStreamConfig s;
  s.model = modelOf(config.model);
  if (config.difop_port < -1 || config.difop_port > 65535)
    throw std::invalid_argument("lidar driver: difop_port " + std::to_string(config.difop_port) +
                                " is not a UDP port (0 = 7788, -1 = none)");
  s.elevations_deg = config.vertical_angles_deg;
  if (!s.elevations_deg.empty() && s.elevations_deg.size() != kBeams)
    throw std::invalid_argument("lidar driver: vertical_angles_deg needs 16 values, got " +
                                std::to_string(s.elevations_deg.size()));
  if (config.time_source == "sensor") s.clock.source = TimeSource::kSensor;
  else if (config.time_source == "utc") s.clock.source = TimeSource::kUtc;
  else if (config.time_source == "host") s.clock.source = TimeSource::kHost;
  else throw std::invalid_argument("lidar driver: time_source '" + config.time_source + "' (sensor, utc or host)");
  if (!(config.max_clock_jump_s > 0) || !(config.max_sweep_duration_s > 0) || !(config.max_firing_gap_s > 0) ||
      !std::isfinite(config.cut_azimuth_deg) || !(config.idle_timeout_s >= 0) ||
      !(config.transport_delay_s >= 0 && config.transport_delay_s < 1))
    throw std::invalid_argument("lidar driver: max_clock_jump_s, max_sweep_duration_s and max_firing_gap_s must be "
                                "> 0, cut_azimuth_deg finite, idle_timeout_s >= 0, transport_delay_s in [0, 1)");
  s.clock.max_jump_s = config.max_clock_jump_s;
  s.clock.sync.transport_delay_s = config.transport_delay_s;
  s.sweep.cut_azimuth_deg = config.cut_azimuth_deg;
  s.sweep.max_sweep_duration_s = config.max_sweep_duration_s;
  s.sweep.max_firing_gap_s = config.max_firing_gap_s;
  s.sweep.sensor = config.sensor_name.empty() ? config.model : config.sensor_name;
  s.sweep.num_beams = beamsOf(s.model);
  s.accept_product_ids = config.accept_product_ids;
  s.dual_return = config.dual_return;
  return s;
}

std::unique_ptr<runtime::MessageSource> makeUdpLidarSource(const UdpLidarConfig& config, std::function<bool()> stop) {
  return std::make_unique<UdpLidarSource>(config, std::move(stop));
}

}  // namespace adit::drivers
