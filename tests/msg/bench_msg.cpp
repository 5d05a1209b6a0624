// What the bus costs per VLP-16 sweep in the lockstep replay (every message is encoded by its publisher and
// decoded by each subscriber): LIDAR_POINTS full-float (before) against compact (after), and FEATURES as it was
// (the whole deskewed sweep and four sets as point_cloud_t) against the lean form. bench_msg --benchmark_filter=.
#include "features/feature_extractor.hpp"
#include "features/preprocess.hpp"
#include "msg/convert.hpp"
#include "msg/encode.hpp"
#include "msg/sweep_codec.hpp"
#include "sim_sweeps.hpp"

#include <benchmark/benchmark.h>

namespace adit {
namespace {

const test::SimSweeps& sweeps() {
  static const test::SimSweeps s = test::simulateSweeps("vlp16", 2);
  return s;
}

template <class Msg>
Msg roundTrip(const Msg& m, std::size_t& bytes) {
  const std::vector<std::uint8_t> b = msg::encode(m);
  bytes = b.size();
  Msg out;
  out.decode(b.data(), 0, static_cast<int>(b.size()));
  return out;
}

void BM_SweepFullFloat(benchmark::State& state) {
  const LidarScan& scan = sweeps().sweeps[1];
  std::size_t bytes = 0;
  for (auto _ : state) benchmark::DoNotOptimize(msg::fromMessage(roundTrip(msg::toMessage(scan), bytes)));
  state.counters["kB"] = static_cast<double>(bytes) / 1e3;
}
BENCHMARK(BM_SweepFullFloat)->Unit(benchmark::kMillisecond);

void BM_SweepCompact(benchmark::State& state) {
  const LidarScan& scan = sweeps().sweeps[1];
  std::size_t bytes = 0;
  for (auto _ : state) {
    LidarScan out;
    benchmark::DoNotOptimize(msg::decodeSweep(roundTrip(msg::encodeSweep(scan, &sweeps().table), bytes), out));
  }
  state.counters["kB"] = static_cast<double>(bytes) / 1e3;
}
BENCHMARK(BM_SweepCompact)->Unit(benchmark::kMillisecond);

void BM_SweepCompactDecodeOnly(benchmark::State& state) {
  const adit::lidar_scan_t m = msg::encodeSweep(sweeps().sweeps[1], &sweeps().table);
  const std::vector<std::uint8_t> b = msg::encode(m);
  for (auto _ : state) {
    msg::SweepMessage s;
    benchmark::DoNotOptimize(s.decode(b.data(), 0, static_cast<int>(b.size())));
  }
}
BENCHMARK(BM_SweepCompactDecodeOnly)->Unit(benchmark::kMillisecond);

const FeatureSet& features() {
  static const FeatureSet f = FeatureExtractor(featureConfigFrom(Config{})).process(sweeps().sweeps[1], {}, MotionPrior{});
  return f;
}

// FEATURES before lean messages: the whole preprocessed sweep and the four sets as full-float point clouds
// (what features_t held, keypoint descriptors aside).
void BM_FeaturesBefore(benchmark::State& state) {
  const FeatureSet& f = features();
  std::size_t bytes = 0, total = 0;
  for (auto _ : state) {
    total = 0;
    for (const std::vector<LidarPoint>* set : {&f.cloud.points, &f.corner_sharp, &f.corner_less_sharp, &f.surf_flat,
                                               &f.surf_less_flat}) {
      benchmark::DoNotOptimize(msg::pointsFromMessage(roundTrip(msg::toMessage(*set, f.cloud), bytes)));
      total += bytes;
    }
  }
  state.counters["kB"] = static_cast<double>(total) / 1e3;
}
BENCHMARK(BM_FeaturesBefore)->Unit(benchmark::kMillisecond);

void BM_FeaturesLean(benchmark::State& state) {
  FeatureSet f = features();
  f.cloud.points = features::voxelDownsample(f.cloud.points, 0.1f);  // as the feature node publishes it
  std::size_t bytes = 0;
  for (auto _ : state) benchmark::DoNotOptimize(msg::fromMessage(roundTrip(msg::toMessage(f), bytes)));
  state.counters["kB"] = static_cast<double>(bytes) / 1e3;
}
BENCHMARK(BM_FeaturesLean)->Unit(benchmark::kMillisecond);

}  // namespace
}  // namespace adit

BENCHMARK_MAIN();
