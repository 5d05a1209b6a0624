// A serial device (a USB-serial IMU) in raw mode at a given baud rate: reads what arrived within a timeout,
// and tells a device that disappeared (unplugged: EIO / ENODEV / hang-up) from a quiet one, so the caller
// can wait and reopen it. termios only.
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>

namespace adit::drivers {

class SerialPort {
 public:
  enum class Read { Data, Timeout, Lost };

  SerialPort() = default;
  ~SerialPort();
  SerialPort(const SerialPort&) = delete;
  SerialPort& operator=(const SerialPort&) = delete;

  // Opens `device` raw (8N1, no flow control, no echo) at `baud`; false with `error` set if it cannot.
  bool open(const std::string& device, int baud, std::string& error);
  void close();
  bool isOpen() const { return fd_ >= 0; }
  // Waits up to timeout_ms for bytes; Data with `got` > 0, Timeout, or Lost (the device is gone: closed).
  Read read(std::uint8_t* buffer, std::size_t size, int timeout_ms, std::size_t& got);

  // True if `baud` is a rate termios can set (9600 ... 4000000).
  static bool supportedBaud(int baud);

 private:
  int fd_ = -1;
};

}  // namespace adit::drivers
