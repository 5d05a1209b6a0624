// Shared by the pcap tests: a capture written from the synthetic lidar (with a lost, a reordered, a late and a
// fragmented packet and foreign traffic, as tcpdump on the host would have written it), read back through
// CaptureLidarReader or through the message source `adit import pcap` runs, and every point checked against
// the firings it came from.
#pragma once

#include "drivers/udp_lidar_source.hpp"
#include "io/capture_writer.hpp"
#include "runtime/source.hpp"
#include "sources/capture_lidar_reader.hpp"
#include "synthetic_lidar.hpp"

#include <cstdint>
#include <functional>
#include <string>
#include <vector>

namespace adit::sources::testing {

constexpr std::int64_t kHost0Ns = 1700000000LL * 1000000000;  // capture clock at packet 0's first firing
constexpr std::int64_t kLatencyNs = 100000;                    // last firing -> capture
constexpr std::uint32_t kSensorIp = 0xC0A801C9, kHostIp = 0xC0A80164, kOtherIp = 0xC0A80105;

struct Recording {
  int packets = 0;
  int lost = -1;        // never written
  int reordered = -1;   // written after packet reordered + 1 (put back in order by the reorder window)
  int late = -1;        // written kReorderWindow + 2 packets late: beyond the window, skipped
  int fragmented = -1;  // split into IP fragments of at most 576 bytes
  bool nanoseconds = false;
  std::vector<std::uint8_t> difop;  // RS-16: a DIFOP packet captured before the data (port 7788)
  std::function<void(std::vector<std::uint8_t>&)> mutate;  // rewrites every data packet
};

std::int64_t captureNs(const drivers::testing::SyntheticLidar& lidar, int k);
std::uint16_t portOf(const drivers::testing::SyntheticLidar& lidar);
io::UdpDatagram datagram(std::int64_t time_ns, std::uint32_t src, std::uint16_t port, std::vector<std::uint8_t> payload);

// The capture file's bytes, with foreign traffic mixed in: an ARP frame, a VLP-16 position packet (port
// 8308) and a datagram from another host to the data port.
std::string writeRecording(const drivers::testing::SyntheticLidar& lidar, const Recording& r);
drivers::UdpLidarConfig configOf(const drivers::testing::SyntheticLidar& lidar);

struct Decoded {
  std::vector<LidarScan> sweeps;
  runtime::Health health;
};
// Through CaptureLidarReader (capture reader, UDP extraction, the live driver's stream).
Decoded decode(const std::string& bytes, const drivers::UdpLidarConfig& config);
// Every message of the source (`adit import pcap`'s), each a compact sweep on LIDAR_POINTS, decoded back.
std::vector<LidarScan> publishedSweeps(runtime::MessageSource& source);

// How far a decoded point may be from its firing: position by range (1 mm if not given), and time (the
// sensor stamps' whole microsecond and the firing-offset rounding).
struct Tolerance {
  std::function<double(double range_m)> position_m;
  double time_ns = 2500.0;
};

// Every point of every sweep is a distinct truth return of a packet that was captured, at its time and
// position (within tolerance; the nearest return wins), with its ring and intensity; and every such return
// after the first pass of the cut angle is there.
void expectPointsMatchTruth(const drivers::testing::SyntheticLidar& lidar, const Recording& r,
                            const std::vector<LidarScan>& sweeps, const Tolerance& tolerance = {});

}  // namespace adit::sources::testing
