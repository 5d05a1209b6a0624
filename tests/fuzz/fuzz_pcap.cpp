// A pcap / pcapng capture file through what `adit import pcap` and adit-lidar-bridge --source pcap run:
// capture reader, link layers, IPv4 reassembly, UDP, and the live driver's packet stream (CaptureLidarReader).
// Input: one byte model (0 VLP-16, 1 RS-16, 2 VLP-32C, 3 HDL-32E, modulo 4), then the file.
#include "io/io_error.hpp"
#include "sources/capture_lidar_reader.hpp"

#include <spdlog/spdlog.h>

#include <sstream>

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  static const bool quiet = (spdlog::set_level(spdlog::level::off), true);  // one log line per bad input: slow
  (void)quiet;
  if (size < 1) return 0;
  adit::drivers::UdpLidarConfig config;
  static const char* const kModels[] = {"vlp16", "rs16", "vlp32c", "hdl32e"};
  config.model = kModels[data[0] % 4];
  std::istringstream in(std::string(reinterpret_cast<const char*>(data + 1), size - 1));
  try {
    adit::sources::CaptureLidarReader reader(in, "fuzz.pcap", config);
    std::vector<adit::LidarScan> sweeps;
    while (reader.read(sweeps)) sweeps.clear();
    (void)reader.health();
  } catch (const adit::io::ReadError&) {
    // not a capture: the one refusal the reader may throw
  }
  return 0;
}
