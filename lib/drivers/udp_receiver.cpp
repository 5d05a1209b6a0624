#include "drivers/udp_receiver.hpp"

#include <arpa/inet.h>
#include <fcntl.h>
#include <netinet/in.h>
#include <poll.h>
#include <sys/socket.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstring>
#include <ctime>
#include <stdexcept>

namespace adit::drivers {
namespace {

constexpr std::size_t kMaxDatagram = 2048;  // lidar packets are 1206 / 1248 bytes

std::string systemError(const std::string& what) { return what + ": " + std::strerror(errno); }

std::int64_t realtimeNs() {
  timespec ts{};
  clock_gettime(CLOCK_REALTIME, &ts);
  return static_cast<std::int64_t>(ts.tv_sec) * 1000000000 + ts.tv_nsec;
}

}  // namespace

UdpReceiver::UdpReceiver(const std::string& address, std::uint16_t port, int recv_buffer_bytes) {
  const std::string where = address + ":" + std::to_string(port);
  sockaddr_in addr{};
  addr.sin_family = AF_INET;
  addr.sin_port = htons(port);
  if (inet_pton(AF_INET, address.c_str(), &addr.sin_addr) != 1)
    throw std::runtime_error("UDP receiver: '" + address + "' is not an IPv4 address");
  fd_ = socket(AF_INET, SOCK_DGRAM | SOCK_NONBLOCK | SOCK_CLOEXEC, 0);
  if (fd_ < 0) throw std::runtime_error(systemError("UDP receiver: socket"));
  const int on = 1;
  // A big buffer rides out scheduling hiccups (a VLP-16 sends ~754 packets/s). Failures are not fatal:
  // the kernel keeps its default and receiveBufferBytes() tells.
  setsockopt(fd_, SOL_SOCKET, SO_RCVBUF, &recv_buffer_bytes, sizeof(recv_buffer_bytes));
  setsockopt(fd_, SOL_SOCKET, SO_TIMESTAMPNS, &on, sizeof(on));
  socklen_t len = sizeof(granted_buffer_);
  getsockopt(fd_, SOL_SOCKET, SO_RCVBUF, &granted_buffer_, &len);
  if (bind(fd_, reinterpret_cast<const sockaddr*>(&addr), sizeof(addr)) != 0) {
    const std::string message = systemError("UDP receiver: bind " + where);
    close(fd_);
    throw std::runtime_error(message);
  }
  sockaddr_in bound{};
  len = sizeof(bound);
  getsockname(fd_, reinterpret_cast<sockaddr*>(&bound), &len);
  port_ = ntohs(bound.sin_port);
}

UdpReceiver::~UdpReceiver() {
  if (fd_ >= 0) close(fd_);
}

UdpReceiver::Result UdpReceiver::receive(std::vector<std::uint8_t>& payload, std::size_t& size,
                                         std::int64_t& receive_ns, int timeout_ms, std::string& error) {
  payload.resize(kMaxDatagram);
  for (int attempt = 0; attempt < 2; ++attempt) {
    iovec iov{payload.data(), payload.size()};
    alignas(cmsghdr) char control[CMSG_SPACE(sizeof(timespec))];
    msghdr msg{};
    msg.msg_iov = &iov;
    msg.msg_iovlen = 1;
    msg.msg_control = control;
    msg.msg_controllen = sizeof(control);
    const ssize_t n = recvmsg(fd_, &msg, MSG_TRUNC);  // MSG_TRUNC: return the datagram's true size
    if (n >= 0) {
      size = static_cast<std::size_t>(n);
      receive_ns = realtimeNs();
      for (cmsghdr* c = CMSG_FIRSTHDR(&msg); c != nullptr; c = CMSG_NXTHDR(&msg, c)) {
        if (c->cmsg_level == SOL_SOCKET && c->cmsg_type == SCM_TIMESTAMPNS) {
          timespec ts{};
          std::memcpy(&ts, CMSG_DATA(c), sizeof(ts));
          receive_ns = static_cast<std::int64_t>(ts.tv_sec) * 1000000000 + ts.tv_nsec;
        }
      }
      payload.resize(std::min(size, payload.size()));
      return Result::kPacket;
    }
    if (errno != EAGAIN && errno != EWOULDBLOCK && errno != EINTR) {
      error = systemError("UDP receive");
      return Result::kError;
    }
    if (attempt == 1) break;
    pollfd p{fd_, POLLIN, 0};
    const int ready = poll(&p, 1, timeout_ms);
    if (ready == 0 || (ready < 0 && errno == EINTR)) return Result::kTimeout;
    if (ready < 0) {
      error = systemError("UDP poll");
      return Result::kError;
    }
  }
  return Result::kTimeout;
}

}  // namespace adit::drivers
