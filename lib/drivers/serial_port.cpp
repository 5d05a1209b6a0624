#include "drivers/serial_port.hpp"

#include <fcntl.h>
#include <poll.h>
#include <termios.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <utility>

namespace adit::drivers {
namespace {

speed_t speedOf(int baud) {
  static const std::pair<int, speed_t> table[] = {
      {9600, B9600},       {19200, B19200},     {38400, B38400},     {57600, B57600},     {115200, B115200},
      {230400, B230400},   {460800, B460800},   {500000, B500000},   {576000, B576000},   {921600, B921600},
      {1000000, B1000000}, {1500000, B1500000}, {2000000, B2000000}, {3000000, B3000000}, {4000000, B4000000}};
  for (const auto& [rate, speed] : table)
    if (rate == baud) return speed;
  return B0;
}

}  // namespace

bool SerialPort::supportedBaud(int baud) { return speedOf(baud) != B0; }

SerialPort::~SerialPort() { close(); }

void SerialPort::close() {
  if (fd_ >= 0) ::close(fd_);
  fd_ = -1;
}

bool SerialPort::open(const std::string& device, int baud, std::string& error) {
  close();
  if (!supportedBaud(baud)) {
    error = "baud rate " + std::to_string(baud) + " is not supported";
    return false;
  }
  const int fd = ::open(device.c_str(), O_RDWR | O_NOCTTY | O_NONBLOCK | O_CLOEXEC);
  if (fd < 0) {
    error = device + ": " + std::strerror(errno);
    return false;
  }
  termios tio{};
  if (::tcgetattr(fd, &tio) != 0) {
    error = device + " is not a serial device: " + std::strerror(errno);
    ::close(fd);
    return false;
  }
  ::cfmakeraw(&tio);
  tio.c_cflag |= CLOCAL | CREAD;
  tio.c_cflag &= ~(CSTOPB | CRTSCTS);
  tio.c_cc[VMIN] = 0;
  tio.c_cc[VTIME] = 0;
  ::cfsetispeed(&tio, speedOf(baud));
  ::cfsetospeed(&tio, speedOf(baud));
  if (::tcsetattr(fd, TCSANOW, &tio) != 0) {
    error = device + ": cannot set raw mode at " + std::to_string(baud) + " baud: " + std::strerror(errno);
    ::close(fd);
    return false;
  }
  fd_ = fd;
  return true;
}

SerialPort::Read SerialPort::read(std::uint8_t* buffer, std::size_t size, int timeout_ms, std::size_t& got) {
  got = 0;
  if (fd_ < 0) return Read::Lost;
  pollfd p{fd_, POLLIN, 0};
  const int ready = ::poll(&p, 1, timeout_ms);
  if (ready == 0) return Read::Timeout;
  if (ready < 0) return errno == EINTR ? Read::Timeout : Read::Lost;
  const ssize_t n = ::read(fd_, buffer, size);
  if (n > 0) {
    got = static_cast<std::size_t>(n);
    return Read::Data;
  }
  if (n < 0 && (errno == EAGAIN || errno == EINTR)) return Read::Timeout;
  // 0 bytes although poll said readable (hang-up), or EIO / ENODEV: the device is gone.
  close();
  return Read::Lost;
}

}  // namespace adit::drivers
