// A bound UDP socket that hands out datagrams with their kernel receive time. Non-blocking, waits with poll.
// Nothing here knows about lidars.
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

namespace adit::drivers {

class UdpReceiver {
 public:
  // Binds address:port (IPv4, "0.0.0.0" = every interface, which also receives the sensors' default
  // broadcast). Asks for a receive buffer of recv_buffer_bytes (the kernel caps it at net.core.rmem_max).
  // Throws std::runtime_error naming the address and the system error.
  UdpReceiver(const std::string& address, std::uint16_t port, int recv_buffer_bytes);
  ~UdpReceiver();
  UdpReceiver(const UdpReceiver&) = delete;
  UdpReceiver& operator=(const UdpReceiver&) = delete;

  enum class Result { kPacket, kTimeout, kError };
  // Waits up to timeout_ms for one datagram. kPacket: `payload` holds it (a datagram larger than the buffer
  // keeps its true size in `size` and its first bytes in `payload`), receive_ns is the kernel's arrival time
  // (ns since 1970, CLOCK_REALTIME; read at return when the kernel gave none). kError: `error` says why.
  Result receive(std::vector<std::uint8_t>& payload, std::size_t& size, std::int64_t& receive_ns, int timeout_ms,
                 std::string& error);

  std::uint16_t port() const { return port_; }
  int receiveBufferBytes() const { return granted_buffer_; }  // what the kernel granted (it doubles the ask)

 private:
  int fd_ = -1;
  std::uint16_t port_ = 0;
  int granted_buffer_ = 0;
};

}  // namespace adit::drivers
