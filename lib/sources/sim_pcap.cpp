#include "sources/sim_pcap.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace adit::sources {

SimVlp16Packets::SimVlp16Packets(const sim::LidarSimulator& lidar, const std::string& what) : lidar_(lidar) {
  const sim::LidarProfile& p = lidar.profile();
  if (p.name != "vlp16" || p.channels() != drivers::kBeams)
    throw std::invalid_argument("sim: " + what + " sends VLP-16 packets; the simulated sensor is '" + p.name + "'");
  const std::vector<std::uint16_t> rings = p.rings();
  channel_of_ring_.assign(rings.size(), 0);
  for (std::size_t j = 0; j < rings.size(); ++j) channel_of_ring_[rings[j]] = static_cast<int>(j);
}

std::vector<io::UdpDatagram> SimVlp16Packets::packetsOf(const LidarScan& scan) {
  const sim::LidarProfile& p = lidar_.profile();
  const int columns = p.columns, last = columns - 1;
  const double period = p.columnPeriod(), rev = p.sweepDuration();
  std::vector<drivers::FiringSequence> sequences(static_cast<std::size_t>(columns));
  for (int c = 0; c < columns; ++c) {
    drivers::FiringSequence& q = sequences[static_cast<std::size_t>(c)];
    q.time_ns = scan.utime * 1000 + std::llround(lidar_.firingOffset(c, 0) * 1e9);
    // The simulator turns clockwise from its cut azimuth (lidar_model.cpp); sensor azimuth grows clockwise.
    const double az = std::fmod(-lidar_.noise().cut_azimuth_deg + 360.0 * c * period / rev, 360.0);
    q.azimuth_deg = az < 0 ? az + 360.0 : az;
  }
  for (const LidarPoint& pt : scan.points) {
    if (pt.ring >= channel_of_ring_.size()) continue;
    const int j = channel_of_ring_[pt.ring];
    const double channel_dt = lidar_.firingOffset(last, j);
    const long c = last + std::lround((static_cast<double>(pt.dt) - channel_dt) / period);
    if (c < 0 || c > last) continue;
    drivers::FiringSequence& q = sequences[static_cast<std::size_t>(c)];
    q.range_m[static_cast<std::size_t>(j)] = pt.p.norm();
    q.intensity[static_cast<std::size_t>(j)] = static_cast<std::uint8_t>(std::clamp(std::lround(pt.intensity), 0L, 255L));
  }
  std::vector<io::UdpDatagram> packets;
  for (const drivers::FiringSequence& q : sequences) {
    std::int64_t first_ns = 0;
    if (!encoder_.add(q, packet_, first_ns)) continue;
    io::UdpDatagram& d = packets.emplace_back();
    d.time_ns = first_ns + drivers::kVlp16PacketDurationNs;
    d.src_ip = 0xC0A801C9;  // 192.168.1.201, the VLP-16's factory address
    d.dst_ip = 0xC0A80164;  // 192.168.1.100, its factory destination
    d.src_port = 2368;
    d.dst_port = 2368;
    d.payload = packet_;
  }
  return packets;
}

SimPcapRecorder::SimPcapRecorder(const sim::LidarSimulator& lidar, std::ostream& out)
    : packetizer_(lidar, "--pcap"), pcap_(out) {}

void SimPcapRecorder::addSweep(const LidarScan& scan) {
  for (const io::UdpDatagram& d : packetizer_.packetsOf(scan)) {
    pcap_.writeUdp(d);
    ++packets_;
  }
}

}  // namespace adit::sources
