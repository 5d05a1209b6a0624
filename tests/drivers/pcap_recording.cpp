#include "pcap_recording.hpp"

#include "msg/sweep_codec.hpp"

#include <adit/lidar_scan_t.hpp>
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <sstream>

namespace adit::sources::testing {

using drivers::testing::Model;
using drivers::testing::SyntheticLidar;
using drivers::testing::TruthFiring;

std::int64_t captureNs(const SyntheticLidar& lidar, int k) {
  return kHost0Ns + k * lidar.packetNs() + lidar.lastFiringNs() + kLatencyNs;
}

std::uint16_t portOf(const SyntheticLidar& lidar) { return lidar.model == Model::kRs16 ? 6699 : 2368; }

io::UdpDatagram datagram(std::int64_t time_ns, std::uint32_t src, std::uint16_t port, std::vector<std::uint8_t> payload) {
  io::UdpDatagram d;
  d.time_ns = time_ns;
  d.src_ip = src;
  d.dst_ip = kHostIp;
  d.src_port = port;
  d.dst_port = port;
  d.payload = std::move(payload);
  return d;
}

std::string writeRecording(const SyntheticLidar& lidar, const Recording& r) {
  std::ostringstream out;
  io::PcapWriter pcap(out, r.nanoseconds);
  std::vector<int> order;
  for (int k = 0; k < r.packets; ++k)
    if (k != r.lost) order.push_back(k);
  if (r.reordered >= 0) {
    const auto at = std::find(order.begin(), order.end(), r.reordered);
    std::iter_swap(at, at + 1);
  }
  if (r.late >= 0) {
    order.erase(std::find(order.begin(), order.end(), r.late));
    order.insert(std::find(order.begin(), order.end(), r.late + static_cast<int>(kReorderWindow) + 2) + 1, r.late);
  }
  if (!r.difop.empty()) pcap.writeUdp(datagram(captureNs(lidar, 0) - 1000000, kSensorIp, 7788, r.difop));
  for (int k : order) {
    const std::int64_t t = captureNs(lidar, k);
    std::vector<std::uint8_t> packet = lidar.packet(k);
    if (r.mutate) r.mutate(packet);
    pcap.writeUdp(datagram(t, kSensorIp, portOf(lidar), packet), k == r.fragmented ? 576 : 1500);
    if (k == 3) {
      std::vector<std::uint8_t> arp(42, 0);
      arp[12] = 0x08;
      arp[13] = 0x06;
      pcap.writeFrame(t + 10, arp);
      pcap.writeUdp(datagram(t + 20, kSensorIp, 8308, std::vector<std::uint8_t>(512, 7)));
      pcap.writeUdp(datagram(t + 30, kOtherIp, portOf(lidar), packet));
    }
  }
  return out.str();
}

drivers::UdpLidarConfig configOf(const SyntheticLidar& lidar) {
  drivers::UdpLidarConfig c;
  const char* names[] = {"vlp16", "rs16", "vlp32c", "hdl32e"};
  c.model = names[static_cast<int>(lidar.model)];
  return c;
}

Decoded decode(const std::string& bytes, const drivers::UdpLidarConfig& config) {
  std::istringstream in(bytes);
  CaptureLidarReader reader(in, "test.pcap", config);
  Decoded d;
  while (reader.read(d.sweeps)) {
  }
  d.health = reader.health();
  return d;
}

void expectPointsMatchTruth(const SyntheticLidar& lidar, const Recording& r, const std::vector<LidarScan>& sweeps,
                            const Tolerance& tolerance) {
  struct Truth {
    TruthFiring f;
    bool used = false;
  };
  const int beams = drivers::testing::beamsOf(lidar.model);
  std::vector<std::vector<Truth>> by_ring(static_cast<std::size_t>(beams));
  std::size_t expected = 0;
  for (int k = 0; k < r.packets; ++k) {
    if (k == r.lost || k == r.late) continue;
    std::vector<TruthFiring> truth;
    lidar.packet(k, &truth);
    for (const TruthFiring& f : truth) {
      if (!f.has_return) continue;
      const double unwrapped = (lidar.az0_centideg + lidar.gap_centideg * static_cast<double>(f.t_ns) /
                                                         static_cast<double>(lidar.blockNs())) / 100.0;
      if (std::floor((unwrapped - 180.0) / 360.0) > std::floor((lidar.az0_centideg / 100.0 - 180.0) / 360.0)) ++expected;
      by_ring[static_cast<std::size_t>(f.ring)].push_back({f});
    }
  }
  const std::int64_t anchor = kHost0Ns + kLatencyNs;
  std::size_t matched = 0;
  for (const LidarScan& s : sweeps) {
    for (const LidarPoint& p : s.points) {
      ASSERT_LT(p.ring, beams);
      const double t = static_cast<double>(s.utime * 1000 - anchor) + static_cast<double>(p.dt) * 1e9;
      auto& candidates = by_ring[p.ring];
      auto best = candidates.end();
      double best_error = 0.0;
      for (auto it = candidates.begin(); it != candidates.end(); ++it) {
        if (it->used || std::abs(static_cast<double>(it->f.t_ns) - t) >= tolerance.time_ns) continue;
        const double error = (it->f.p - p.p.cast<double>()).norm();
        const double allowed = tolerance.position_m ? tolerance.position_m(it->f.range_m) : 1e-3;
        if (error < allowed && (best == candidates.end() || error < best_error)) {
          best = it;
          best_error = error;
        }
      }
      ASSERT_NE(best, candidates.end()) << "no truth firing of ring " << p.ring << " at " << t << " ns, " << p.p.transpose();
      best->used = true;
      EXPECT_EQ(p.intensity, best->f.intensity);
      ++matched;
    }
  }
  EXPECT_EQ(matched, expected);
}

std::vector<LidarScan> publishedSweeps(runtime::MessageSource& source) {
  runtime::OutgoingMessage m;
  std::vector<LidarScan> sweeps;
  std::int64_t last_utime = 0;
  while (source.next(m)) {
    EXPECT_EQ(m.channel, "LIDAR_POINTS");
    EXPECT_GT(m.utime, last_utime);
    last_utime = m.utime;
    adit::lidar_scan_t msg;
    LidarScan scan;
    if (msg.decode(m.data.data(), 0, static_cast<int>(m.data.size())) <= 0) {
      ADD_FAILURE() << "message " << sweeps.size() << " is not a lidar_scan_t";
    } else if (const std::string error = msg::decodeSweep(msg, scan); !error.empty()) {
      ADD_FAILURE() << "message " << sweeps.size() << ": " << error;
    }
    sweeps.push_back(std::move(scan));
  }
  return sweeps;
}

}  // namespace adit::sources::testing
