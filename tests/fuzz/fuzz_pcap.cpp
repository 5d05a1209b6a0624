// A pcap / pcapng capture file through what `adit import pcap` and adit-lidar-bridge --source pcap run:
// capture reader, link layers, IPv4 reassembly, UDP, and the live driver's packet stream (CaptureLidarReader).
// Input: one byte model (even VLP-16, odd RS-16), then the file.
#include "io/io_error.hpp"
#include "sources/capture_lidar_reader.hpp"

#include <spdlog/spdlog.h>

#include <sstream>

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  static const bool quiet = (spdlog::set_level(spdlog::level::off), true);  // one log line per bad input: slow
  (void)quiet;
  if (size < 1) return 0;
  adit::drivers::UdpLidarConfig config;
  config.model = data[0] % 2 ? "rs16" : "vlp16";
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
