#include "sources/capture_lidar_reader.hpp"

#include "drivers/rs16_decoder.hpp"

#include <spdlog/spdlog.h>

#include <algorithm>

namespace adit::sources {
namespace {

// What counts as damage (Health::errors) rather than other traffic.
bool isDamage(const std::string& counter) {
  return counter == "truncated_record" || counter == "corrupt_record" || counter == "unknown_interface" ||
         counter == "bad_timestamp_resolution" || counter == "snapped" || counter == "bad_ip_header" ||
         counter == "bad_udp_header" || counter == "fragments_dropped";
}

drivers::LidarStreamConfig streamConfig(const drivers::UdpLidarConfig& config) {
  drivers::LidarStreamConfig s = drivers::streamConfigOf(config);
  s.host_time_fallback = true;
  return s;
}

}  // namespace

CaptureLidarReader::CaptureLidarReader(std::istream& in, std::string name, const drivers::UdpLidarConfig& config)
    : name_(std::move(name)), model_(drivers::streamConfigOf(config).model), reader_(in, name_), stream_(streamConfig(config)), port_(drivers::dataPortOf(config)) {
  if (config.model == "rs16" && config.difop_port >= 0)  // range checked by streamConfigOf
    difop_port_ = config.difop_port > 0 ? config.difop_port : drivers::kRs16DifopPort;
  if (!config.sensor_address.empty()) {
    if (!io::parseIpv4(config.sensor_address, sensor_ip_))
      throw std::invalid_argument("lidar driver: sensor_address '" + config.sensor_address + "' is not an IPv4 address");
    have_sensor_ = true;
  }
}

bool CaptureLidarReader::read(std::vector<LidarScan>& sweeps) {
  const std::size_t before = sweeps.size();
  while (sweeps.size() == before) {
    if (finished_) return false;
    if (!reader_.next(frame_)) {
      while (!window_.empty()) release(sweeps);
      stream_.finish(sweeps);
      finished_ = true;
      break;
    }
    if (!extractor_.push(frame_, datagram_)) continue;
    if (datagram_.dst_port == difop_port_ && (!have_sensor_ || datagram_.src_ip == sensor_ip_)) {
      stream_.pushDeviceInfo(datagram_.payload.data(), datagram_.payload.size());
      continue;
    }
    if (datagram_.dst_port != port_) {
      ++counters_["other_port"];
      continue;
    }
    if (have_sensor_ && datagram_.src_ip != sensor_ip_) {
      ++counters_["other_host"];
      continue;
    }
    hold(sweeps);
  }
  return sweeps.size() > before || !finished_;
}

void CaptureLidarReader::hold(std::vector<LidarScan>& sweeps) {
  std::int64_t key = 0;
  if (!drivers::packetStampKey(model_, datagram_.payload.data(), datagram_.payload.size(), key)) {
    // No stamp to order by (a wrong size): after everything held, so the stream counts it in turn.
    key = window_.empty() ? reference_key_ : window_.back().key;
  } else {
    if (!have_reference_) {
      reference_key_ = key;
      have_reference_ = true;
    }
    if (!have_sensor_) {  // the first packet of the sensor's size names the sensor
      have_sensor_ = true;
      sensor_ip_ = datagram_.src_ip;
      spdlog::info("capture '{}': lidar packets from {} to port {}", name_, io::ipv4ToString(sensor_ip_), port_);
    }
    key = drivers::unwrapStampKey(model_, key, reference_key_);
  }
  auto at = std::upper_bound(window_.begin(), window_.end(), key, [](std::int64_t k, const Held& h) { return k < h.key; });
  if (at != window_.end()) ++counters_["reordered"];
  window_.insert(at, Held{key, datagram_});
  if (window_.size() > kReorderWindow) release(sweeps);
}

void CaptureLidarReader::release(std::vector<LidarScan>& sweeps) {
  const Held held = std::move(window_.front());
  window_.pop_front();
  reference_key_ = held.key;
  stream_.push(held.datagram.payload.data(), held.datagram.payload.size(), held.datagram.time_ns, sweeps);
}

runtime::Health CaptureLidarReader::health() const {
  runtime::Health h = stream_.health();
  const auto add = [&h](const std::map<std::string, std::int64_t>& counters) {
    for (const auto& [name, n] : counters) {
      if (name == "frames" || name == "fragments" || name == "reassembled" || name == "reordered") {
        if (name == "reordered") h.counters[name] += n;  // an event, not a problem
        continue;
      }
      h.counters[name] += n;
      if (isDamage(name)) h.errors += n;
    }
  };
  add(reader_.counters());
  add(extractor_.counters());
  add(counters_);
  if (!reader_.lastError().empty()) h.last_error = reader_.lastError();
  return h;
}

std::string CaptureLidarReader::summary() const {
  const runtime::Health h = health();
  const auto count = [this](const char* name) {
    const auto it = extractor_.counters().find(name);
    return it == extractor_.counters().end() ? std::int64_t{0} : it->second;
  };
  std::string line = "capture '" + name_ + "': " + std::to_string(count("frames")) + " frames, " +
                     std::to_string(count("reassembled")) + " datagrams reassembled from fragments, " +
                     std::to_string(h.inputs) + " lidar packets, " + std::to_string(h.outputs) + " sweeps;";
  for (const auto& [name, n] : h.counters)
    if (n > 0) line += " " + name + "=" + std::to_string(n);
  return line;
}

}  // namespace adit::sources
