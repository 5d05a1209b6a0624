// The simulator's lidar on its own UDP link, wired as a real VLP-16 is: `adit sim --live --lidar-udp HOST:PORT`
// sends each sweep as the VLP-16 data packets the sensor would have sent (SimVlp16Packets), at the sweep's
// due time, instead of publishing LIDAR_POINTS on LCM; adit-lidar-bridge decodes them as it would a sensor's.
// That is the path a real sensor's data takes, and the link of a robot that can lose packets (a cable, a
// switch): the stages' own bus stays on the computer (ttl=0). The other channels (IMU, GROUND_TRUTH, ...)
// are published as before. Give the SimSource SimChannels::sweep_bytes = false: the sweeps need not be encoded.
// Time: the packets carry the sweep's own stamps (microseconds past the hour), so the bridge reads them with
// lidar_driver.time_source utc and the simulator's clock must be the host's (cmd_sim starts it at the wall
// clock and keeps the run within half an hour of it).
#pragma once

#include "drivers/udp_sender.hpp"
#include "sources/sim_pcap.hpp"
#include "sources/sim_source.hpp"

#include <memory>
#include <string>

namespace adit::sources {

class SimLidarUdpSource : public runtime::MessageSource {
 public:
  // Throws std::invalid_argument unless the simulated head is a VLP-16, std::runtime_error if no socket.
  SimLidarUdpSource(SimSource& sim, const std::string& host, std::uint16_t port);

  bool next(runtime::OutgoingMessage& message) override;
  // The simulator's counters and `lidar_packets_sent`, `lidar_send_errors` (the first error's text in
  // last_error): a sensor link does not stop for a refused datagram.
  const runtime::Health& health() const override;
  double progress() const override { return sim_.progress(); }

 private:
  struct Link {
    drivers::UdpSender sender;
    std::int64_t sent = 0, errors = 0;
    std::string first_error;
    Link(const std::string& host, std::uint16_t port) : sender(host, port) {}
  };
  SimSource& sim_;
  SimVlp16Packets packetizer_;
  std::shared_ptr<Link> link_;
  std::vector<io::UdpDatagram> pending_;  // the packets of the sweep the simulator just made
  mutable runtime::Health health_;
};

}  // namespace adit::sources
