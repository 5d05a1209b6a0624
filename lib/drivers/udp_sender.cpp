#include "drivers/udp_sender.hpp"

#include <arpa/inet.h>
#include <netinet/in.h>
#include <sys/socket.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <stdexcept>

namespace adit::drivers {

static_assert(sizeof(sockaddr_in) <= 16, "UdpSender keeps a sockaddr_in in 16 bytes");

UdpSender::UdpSender(const std::string& address, std::uint16_t port)
    : where_(address + ":" + std::to_string(port)) {
  sockaddr_in to{};
  to.sin_family = AF_INET;
  to.sin_port = htons(port);
  if (inet_pton(AF_INET, address.c_str(), &to.sin_addr) != 1)
    throw std::runtime_error("UDP sender: '" + address + "' is not an IPv4 address");
  std::memcpy(address_, &to, sizeof(to));
  fd_ = socket(AF_INET, SOCK_DGRAM | SOCK_CLOEXEC, 0);
  if (fd_ < 0) throw std::runtime_error("UDP sender: socket: " + std::string(std::strerror(errno)));
}

UdpSender::~UdpSender() {
  if (fd_ >= 0) close(fd_);
}

bool UdpSender::send(const std::uint8_t* data, std::size_t size, std::string& error) {
  const ssize_t sent = sendto(fd_, data, size, 0, reinterpret_cast<const sockaddr*>(address_), sizeof(sockaddr_in));
  if (sent == static_cast<ssize_t>(size)) return true;
  error = "UDP sender: to " + where_ + ": " + (sent < 0 ? std::strerror(errno) : "datagram cut short");
  return false;
}

void parseUdpAddress(const std::string& text, std::string& host, std::uint16_t& port) {
  const auto colon = text.rfind(':');
  const auto bad = [&](const std::string& why) {
    return std::invalid_argument("'" + text + "' is not HOST:PORT (" + why + ")");
  };
  if (colon == std::string::npos) throw bad("no port");
  if (colon == 0) throw bad("no host");
  const std::string digits = text.substr(colon + 1);
  if (digits.empty() || digits.size() > 5 || digits.find_first_not_of("0123456789") != std::string::npos)
    throw bad("the port is not a number");
  const long value = std::stol(digits);
  if (value < 1 || value > 65535) throw bad("the port is not 1-65535");
  in_addr probe{};
  host = text.substr(0, colon);
  if (inet_pton(AF_INET, host.c_str(), &probe) != 1) throw bad("the host is not an IPv4 address");
  port = static_cast<std::uint16_t>(value);
}

}  // namespace adit::drivers
