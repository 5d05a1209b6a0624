#include "sources/sim_lidar_udp.hpp"

namespace adit::sources {

SimLidarUdpSource::SimLidarUdpSource(SimSource& sim, const std::string& host, std::uint16_t port)
    : sim_(sim), packetizer_(sim.simulator().lidar(), "--lidar-udp"), link_(std::make_shared<Link>(host, port)) {
  sim_.addSweepObserver([this](const LidarScan& scan) { pending_ = packetizer_.packetsOf(scan); });
}

bool SimLidarUdpSource::next(runtime::OutgoingMessage& message) {
  if (!sim_.next(message)) return false;
  if (message.channel != sim_.channels().lidar) return true;
  // The sweep leaves as packets; the message keeps its time (it paces the run) and no bytes for LCM.
  message.data.clear();
  message.send = [link = link_, packets = std::move(pending_)] {
    for (const io::UdpDatagram& d : packets) {
      std::string error;
      if (link->sender.send(d.payload.data(), d.payload.size(), error)) {
        ++link->sent;
      } else if (link->errors++ == 0) {
        link->first_error = error;
      }
    }
  };
  pending_.clear();
  return true;
}

const runtime::Health& SimLidarUdpSource::health() const {
  health_ = sim_.health();
  health_.counters["lidar_packets_sent"] = link_->sent;
  health_.counters["lidar_send_errors"] = link_->errors;
  if (link_->errors > 0 && health_.last_error.empty()) health_.last_error = link_->first_error;
  return health_;
}

}  // namespace adit::sources
