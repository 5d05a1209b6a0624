// VLP-16 / RS-16 / VLP-32C / HDL-32E UDP payloads through the driver chain adit-lidar-bridge runs: decoder
// (and the RS-16's DIFOP packets), packet clock and sweep assembler (LidarPacketStream).
// Input: one byte model (modulo 4: VLP-16, RS-16, VLP-32C, HDL-32E), then packets as [uint16 size][uint16 us
// since the previous packet][payload]; a size with its top bit set is a device-info packet (the DIFOP port)
// of 15-bit size.
#include "drivers/lidar_stream.hpp"
#include "fuzz_input.hpp"

#include <spdlog/spdlog.h>

#include <stdexcept>

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  static const bool quiet = (spdlog::set_level(spdlog::level::off), true);  // one log line per bad input: slow
  (void)quiet;
  adit::fuzz::Input in(data, size);
  adit::drivers::LidarStreamConfig config;
  using adit::drivers::LidarModel;
  static const LidarModel kModels[] = {LidarModel::kVlp16, LidarModel::kRs16, LidarModel::kVlp32c, LidarModel::kHdl32e};
  config.model = kModels[in.byte() % 4];
  adit::drivers::LidarPacketStream stream(config);
  std::vector<adit::LidarScan> sweeps;
  std::int64_t host_ns = 1700000000LL * 1000000000LL;
  while (in.remaining() > 4) {
    const std::uint16_t field = in.u16();
    host_ns += static_cast<std::int64_t>(in.u16()) * 1000;
    const std::string packet = in.bytes(field & 0x7FFF);
    const auto* bytes = reinterpret_cast<const std::uint8_t*>(packet.data());
    if (field & 0x8000)
      stream.pushDeviceInfo(bytes, packet.size());
    else
      stream.push(bytes, packet.size(), host_ns, sweeps);
  }
  return 0;
}
