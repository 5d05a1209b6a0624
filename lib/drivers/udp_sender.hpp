// A UDP socket that sends datagrams to one IPv4 address and port: what a lidar does on its link. For the
// simulator's sensor packets (`adit sim --live --lidar-udp`) and tests. Nothing here knows about lidars.
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>

namespace adit::drivers {

class UdpSender {
 public:
  // Throws std::runtime_error naming the address when it is not IPv4 or no socket can be made.
  UdpSender(const std::string& address, std::uint16_t port);
  ~UdpSender();
  UdpSender(const UdpSender&) = delete;
  UdpSender& operator=(const UdpSender&) = delete;

  // Sends one datagram; false with `error` set when the kernel refused it (nobody is listening on a local
  // port, a full send queue): a sensor's link does not stop for that, the caller counts it.
  bool send(const std::uint8_t* data, std::size_t size, std::string& error);

 private:
  int fd_ = -1;
  std::string where_;
  unsigned char address_[16] = {};  // sockaddr_in, kept opaque to keep socket headers out of this one
};

// "HOST:PORT" with an IPv4 host and a port 1-65535 (e.g. "127.0.0.1:2368"); throws std::invalid_argument.
void parseUdpAddress(const std::string& text, std::string& host, std::uint16_t& port);

}  // namespace adit::drivers
