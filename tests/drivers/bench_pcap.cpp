// pcap decode throughput: a capture of 10 s of VLP-16 packets (7 540 packets, 9.5 MB, Ethernet, every 50th
// datagram in IP fragments) read from memory through what `adit import pcap` runs per packet: capture
// records, UDP extraction, decode, packet clock, sweep assembly (CaptureLidarReader). items/s = packets/s;
// realtime_factor = packets/s over the 754 packets/s a VLP-16 sends (single return, 10 Hz).
#include "io/capture_writer.hpp"
#include "sources/capture_lidar_reader.hpp"
#include "synthetic_lidar.hpp"

#include <benchmark/benchmark.h>
#include <spdlog/spdlog.h>

#include <sstream>

namespace adit::sources {
namespace {

constexpr int kPackets = 7540;

std::string capture() {
  drivers::testing::SyntheticLidar lidar;
  std::ostringstream out;
  io::PcapWriter pcap(out);
  for (int k = 0; k < kPackets; ++k) {
    io::UdpDatagram d;
    d.time_ns = 1700000000LL * 1000000000 + k * lidar.packetNs() + lidar.lastFiringNs();
    d.src_ip = 0xC0A801C9;
    d.dst_ip = 0xC0A80164;
    d.src_port = d.dst_port = 2368;
    d.payload = lidar.packet(k);
    pcap.writeUdp(d, k % 50 == 0 ? 576 : 1500);
  }
  return out.str();
}

void BM_PcapDecodeVlp16(benchmark::State& state) {
  spdlog::set_level(spdlog::level::warn);
  const std::string bytes = capture();
  drivers::UdpLidarConfig config;
  std::int64_t sweeps = 0;
  for (auto _ : state) {
    std::istringstream in(bytes);
    CaptureLidarReader reader(in, "bench.pcap", config);
    std::vector<LidarScan> out;
    while (reader.read(out)) {
      sweeps += static_cast<std::int64_t>(out.size());
      out.clear();
    }
    if (reader.health().inputs != kPackets) state.SkipWithError("packets lost");
  }
  const double packets = static_cast<double>(state.iterations()) * kPackets;
  state.SetItemsProcessed(static_cast<std::int64_t>(packets));
  state.SetBytesProcessed(static_cast<std::int64_t>(state.iterations()) * static_cast<std::int64_t>(bytes.size()));
  state.counters["realtime_factor"] = benchmark::Counter(packets / 754.0, benchmark::Counter::kIsRate);
  state.counters["sweeps"] = static_cast<double>(sweeps) / static_cast<double>(state.iterations());
}
BENCHMARK(BM_PcapDecodeVlp16)->Unit(benchmark::kMillisecond);

}  // namespace
}  // namespace adit::sources

BENCHMARK_MAIN();
