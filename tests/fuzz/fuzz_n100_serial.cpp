// The N100 serial IMU's byte stream through what adit-imu-bridge --source serial runs on it: the FDILink
// frame parser (any split of the bytes), the IMU / AHRS payload decoders and the device-clock sync.
// Input: one byte chunk size (1..256), then the serial bytes.
#include "drivers/clock_sync.hpp"
#include "drivers/fdilink.hpp"
#include "fuzz_input.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  adit::fuzz::Input in(data, size);
  const std::size_t chunk = static_cast<std::size_t>(in.byte()) + 1;
  const std::string bytes = in.rest();
  adit::drivers::FdiLinkParser parser;
  adit::drivers::DeviceClockSync sync;
  std::int64_t host_us = 1700000000000000;
  for (std::size_t i = 0; i < bytes.size(); i += chunk) {
    host_us += 5000;
    const std::size_t n = std::min(chunk, bytes.size() - i);
    parser.push(reinterpret_cast<const std::uint8_t*>(bytes.data() + i), n, [&](const adit::drivers::FdiFrame& f) {
      if (auto imu = adit::drivers::decodeFdiImu(f.payload)) sync.stamp(imu->device_us, host_us);
      adit::drivers::decodeFdiAhrs(f.payload);
    });
  }
  return 0;
}
