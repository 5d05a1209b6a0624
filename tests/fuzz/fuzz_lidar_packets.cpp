// VLP-16 / RS-16 UDP payloads through the driver chain adit-lidar-bridge runs: decoder, packet clock and
// sweep assembler (LidarPacketStream).
// Input: one byte model (even VLP-16, odd RS-16), then packets as [uint16 size][uint16 us since the
// previous packet][payload].
#include "drivers/lidar_stream.hpp"
#include "fuzz_input.hpp"

#include <spdlog/spdlog.h>

#include <stdexcept>

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  static const bool quiet = (spdlog::set_level(spdlog::level::off), true);  // one log line per bad input: slow
  (void)quiet;
  adit::fuzz::Input in(data, size);
  adit::drivers::LidarStreamConfig config;
  config.model = in.byte() % 2 ? adit::drivers::LidarModel::kRs16 : adit::drivers::LidarModel::kVlp16;
  adit::drivers::LidarPacketStream stream(config);
  std::vector<adit::LidarScan> sweeps;
  std::int64_t host_ns = 1700000000LL * 1000000000LL;
  while (in.remaining() > 4) {
    const std::size_t n = in.u16();
    host_ns += static_cast<std::int64_t>(in.u16()) * 1000;
    const std::string packet = in.bytes(n);
    stream.push(reinterpret_cast<const std::uint8_t*>(packet.data()), packet.size(), host_ns, sweeps);
  }
  return 0;
}
