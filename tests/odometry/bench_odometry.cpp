// Per-sweep time of scan-to-scan odometry and scan-to-map mapping, one thread, on 16-beam simulated roadway
// sweeps (lib/sim vlp16, features from FeatureExtractor) and 64-beam kitti_mini 02. Targets for 16 beams:
// odometry <= 10 ms, mapping <= 30 ms per sweep. Feature extraction is done before timing.
#include "features/feature_extractor.hpp"
#include "features/link3d_match.hpp"
#include "io/kitti.hpp"
#include "mapping/scan_to_map.hpp"
#include "odometry/scan_to_scan.hpp"
#include "sim_run.hpp"

#include <benchmark/benchmark.h>

#include <memory>
#include <string>

namespace adit {
namespace {

struct Sequence {
  std::vector<FeatureSet> features;
  std::vector<PoseEstimate> odometry;  // odometry of each sweep, to feed the mapper
  MapperConfig mapper;
};

void computeOdometry(Sequence& s) {
  ScanToScanOdometry odom;
  for (const FeatureSet& f : s.features) s.odometry.push_back(odom.process(f));
}

const Sequence& vlp16() {
  static const Sequence s = [] {
    Sequence q;
    // 6 s of roadway-straight after the 2 s standstill: 60 sweeps at ~1.3 m/s.
    q.features = test::simulateRun("roadway-straight", "vlp16", 8.0).features;
    q.features.erase(q.features.begin(), q.features.begin() + 20);
    computeOdometry(q);
    return q;
  }();
  return s;
}

const Sequence& kitti02() {
  static const Sequence s = [] {
    Sequence q;
    const io::KittiSequence seq = io::KittiSequence::open(std::string(ADIT_SHARED_DATA_DIR) + "/kitti_mini", "02");
    const FeatureExtractor fx{FeatureConfig{}};
    ScanToScanOdometry odom;
    for (std::size_t i = 0; i < seq.size(); ++i) {
      const LidarScan scan = seq.scan(i);
      MotionPrior motion;
      motion.T_prev_curr = odom.predictMotion(scan.utime);
      motion.dt_s = 0.1;
      motion.valid = i > 1;
      q.features.push_back(fx.process(scan, {}, motion));
      odom.process(q.features.back());
    }
    q.mapper.corner_resolution_m = 0.4;
    q.mapper.surf_query_resolution_m = 0.8;  // the map keeps 0.4 m (launch/sensors/hdl64.yaml)
    computeOdometry(q);
    return q;
  }();
  return s;
}

// Processes the sequence's sweeps in order, one per benchmark iteration; restarts (untimed) at the end.
void runOdometry(benchmark::State& state, const Sequence& s) {
  auto odom = std::make_unique<ScanToScanOdometry>();
  std::size_t i = 0;
  odom->process(s.features[i++]);
  for (auto _ : state) {
    benchmark::DoNotOptimize(odom->process(s.features[i++]));
    if (i == s.features.size()) {
      state.PauseTiming();
      odom = std::make_unique<ScanToScanOdometry>();
      i = 0;
      odom->process(s.features[i++]);
      state.ResumeTiming();
    }
  }
  state.counters["sharp+flat"] = static_cast<double>(s.features[1].corner_sharp.size() + s.features[1].surf_flat.size());
}

void runMapping(benchmark::State& state, const Sequence& s) {
  auto mapper = std::make_unique<ScanToMapMapper>(s.mapper);
  std::size_t i = 0;
  // Warm up past the first sweeps so the local map is populated as in steady state.
  for (; i < 3; ++i) mapper->process(s.features[i], s.odometry[i]);
  for (auto _ : state) {
    benchmark::DoNotOptimize(mapper->process(s.features[i], s.odometry[i]));
    if (++i == s.features.size()) {
      state.PauseTiming();
      mapper = std::make_unique<ScanToMapMapper>(s.mapper);
      for (i = 0; i < 3; ++i) mapper->process(s.features[i], s.odometry[i]);
      state.ResumeTiming();
    }
  }
  state.counters["map_points"] = static_cast<double>(mapper->surfMap().numPoints() + mapper->cornerMap().numPoints());
}

void BM_Odometry_VLP16_Sim(benchmark::State& state) { runOdometry(state, vlp16()); }
void BM_Mapping_VLP16_Sim(benchmark::State& state) { runMapping(state, vlp16()); }
void BM_Odometry_HDL64_Kitti02(benchmark::State& state) { runOdometry(state, kitti02()); }
void BM_Mapping_HDL64_Kitti02(benchmark::State& state) { runMapping(state, kitti02()); }

BENCHMARK(BM_Odometry_VLP16_Sim)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_Mapping_VLP16_Sim)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_Odometry_HDL64_Kitti02)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_Mapping_HDL64_Kitti02)->Unit(benchmark::kMillisecond);

}  // namespace
}  // namespace adit

BENCHMARK_MAIN();
