// An IMU on a serial port as an adit::runtime::MessageSource (adit-imu-bridge --source serial): reads the
// WHEELTEC N100's binary protocol (drivers/fdilink.hpp) or a text protocol (one sample a line,
// `t gx gy gz ax ay az [mx my mz]` with t in device seconds, as io/imu_csv.hpp), stamps each sample on the
// host's clock (drivers/clock_sync.hpp, or the raw receive time), and yields one encoded imu_t per sample.
// Noise, CRC errors and split frames are counted and resynchronised over; a device that disappears (USB
// unplugged) is reopened every reopen_period_s while STATUS says so ("device_lost", "reopened").
#pragma once

#include "drivers/clock_sync.hpp"
#include "io/imu_csv.hpp"
#include "runtime/source.hpp"

#include <functional>
#include <memory>
#include <string>

namespace adit::drivers {

struct SerialImuConfig {
  std::string device = "/dev/ttyUSB0";
  int baud = 921600;
  std::string protocol = "n100";  // "n100" (FDILink binary) or "text"
  std::string channel = "IMU";
  std::string clock = "sync";      // "sync": device stamps mapped to host time; "host": receive time as is
  // Fixed delay from sampling to the host's receive (subtracted); < 0 = a frame's bytes at the baud rate.
  double transport_delay_s = -1;
  double reopen_period_s = 1.0;
  double max_ahrs_age_s = 0.02;   // an AHRS orientation this close to an IMU sample is attached to it
  io::ImuCsvConfig text;          // scales of the text protocol
  ClockSyncConfig sync;           // (its transport_delay_s is set from the one above)
};

// Throws std::invalid_argument on a bad protocol, clock or baud rate. Never throws for a missing device: it
// waits for it. next() returns false on SIGINT/SIGTERM or when `stop` returns true. `host_clock` (tests)
// replaces the wall clock, in microseconds.
std::unique_ptr<runtime::MessageSource> makeSerialImuSource(const SerialImuConfig& config,
                                                            std::function<bool()> stop = {},
                                                            std::function<std::int64_t()> host_clock = {});

}  // namespace adit::drivers
