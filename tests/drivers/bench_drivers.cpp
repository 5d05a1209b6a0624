// Cost of the driver per packet: decoding alone, and decoding + packet clock + sweep assembly (what a live
// source does per datagram). A VLP-16 sends ~754 packets/s (single return), an RS-16 ~750.
#include "drivers/lidar_stream.hpp"
#include "drivers/rs16_decoder.hpp"
#include "drivers/vlp16_decoder.hpp"
#include "synthetic_lidar.hpp"

#include <benchmark/benchmark.h>

namespace adit::drivers {
namespace {

using testing::Model;
using testing::SyntheticLidar;

std::vector<std::vector<std::uint8_t>> packets(Model model, int n) {
  SyntheticLidar lidar;
  lidar.model = model;
  lidar.stamp0_us = model == Model::kVlp16 ? 1000 : testing::kRs16TestEpochUs;
  std::vector<std::vector<std::uint8_t>> out;
  for (int k = 0; k < n; ++k) out.push_back(lidar.packet(k));
  return out;
}

void BM_DecodeVlp16(benchmark::State& state) {
  const auto p = packets(Model::kVlp16, 75);
  Vlp16Decoder decoder;
  DecodedPacket out;
  std::size_t i = 0;
  for (auto _ : state) {
    benchmark::DoNotOptimize(decoder.decode(p[i].data(), p[i].size(), out));
    i = (i + 1) % p.size();
  }
  state.SetItemsProcessed(static_cast<std::int64_t>(state.iterations()));
}
BENCHMARK(BM_DecodeVlp16);

void BM_DecodeRs16(benchmark::State& state) {
  const auto p = packets(Model::kRs16, 75);
  Rs16Decoder decoder;
  DecodedPacket out;
  std::size_t i = 0;
  for (auto _ : state) {
    benchmark::DoNotOptimize(decoder.decode(p[i].data(), p[i].size(), out));
    i = (i + 1) % p.size();
  }
  state.SetItemsProcessed(static_cast<std::int64_t>(state.iterations()));
}
BENCHMARK(BM_DecodeRs16);

// One revolution (75 packets) through decode + clock + sweep assembly, the sweep included. Host time mode,
// so replaying the same packets keeps going forward in time.
void BM_StreamVlp16Revolution(benchmark::State& state) {
  const auto p = packets(Model::kVlp16, 75);
  LidarStreamConfig config;
  config.clock.source = TimeSource::kHost;
  LidarPacketStream stream(config);
  std::vector<LidarScan> sweeps;
  std::int64_t t = 1700000000LL * 1000000000;
  for (auto _ : state) {
    for (const auto& packet : p) stream.push(packet.data(), packet.size(), t += 1327104, sweeps);
    sweeps.clear();
  }
  if (stream.health().drops > 1) state.SkipWithError("packets dropped");
  state.SetItemsProcessed(static_cast<std::int64_t>(state.iterations()) * 75);
}
BENCHMARK(BM_StreamVlp16Revolution)->Unit(benchmark::kMillisecond);

}  // namespace
}  // namespace adit::drivers

BENCHMARK_MAIN();
