// Speed of the whole feature stage (preprocess, deskew, LOAM, LinK3D keypoints + descriptors), one thread:
// a simulated 16-beam sweep (target <= 5 ms) and a real 64-beam KITTI sweep (target <= 25 ms).
#include "features/feature_extractor.hpp"
#include "features/link3d_match.hpp"
#include "features/link3d.hpp"
#include "features/loam_features.hpp"
#include "features/preprocess.hpp"
#include "features/smoothness.hpp"
#include "io/kitti.hpp"
#include "synthetic_scans.hpp"

#include <benchmark/benchmark.h>

#include <random>

namespace adit {
namespace {

// 16-beam VLP-16-like sweep in a pillared hall, 1 cm range noise, moving 1.5 m/s (deskewed by the prior).
LidarScan sixteenBeamSweep() {
  LidarScan scan = test::scanScene(test::pillarHall(), [](double t) {
    Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
    T.translation() = Eigen::Vector3d(1.5 * t, 0.0, 0.0);
    return T;
  });
  std::mt19937 rng(1);
  std::normal_distribution<float> noise(0.0f, 0.01f);
  for (LidarPoint& p : scan.points) p.p *= 1.0f + noise(rng) / p.p.norm();
  return scan;
}

MotionPrior walkingPrior() {
  MotionPrior m;
  m.T_prev_curr.translation() = Eigen::Vector3d(0.15, 0.0, 0.0);
  m.dt_s = 0.1;
  m.valid = true;
  return m;
}

void BM_FeatureStage16Beam(benchmark::State& state) {
  const LidarScan scan = sixteenBeamSweep();
  const FeatureExtractor fx{FeatureConfig{}};
  const MotionPrior prior = walkingPrior();
  std::size_t keypoints = 0;
  for (auto _ : state) {
    FeatureSet f = fx.process(scan, {}, prior);
    keypoints = f.keypoints.size();
    benchmark::DoNotOptimize(f);
  }
  state.counters["points"] = static_cast<double>(scan.points.size());
  state.counters["keypoints"] = static_cast<double>(keypoints);
}
BENCHMARK(BM_FeatureStage16Beam)->Unit(benchmark::kMillisecond);

void BM_FeatureStageKitti64Beam(benchmark::State& state) {
  const io::KittiSequence seq = io::KittiSequence::open(std::string(ADIT_SHARED_DATA_DIR) + "/kitti_mini", "00");
  const LidarScan scan = seq.scan(0);
  const FeatureExtractor fx{FeatureConfig{}};
  std::size_t keypoints = 0;
  for (auto _ : state) {
    FeatureSet f = fx.process(scan, {}, MotionPrior{});
    keypoints = f.keypoints.size();
    benchmark::DoNotOptimize(f);
  }
  state.counters["points"] = static_cast<double>(scan.points.size());
  state.counters["keypoints"] = static_cast<double>(keypoints);
}
BENCHMARK(BM_FeatureStageKitti64Beam)->Unit(benchmark::kMillisecond);

// The parts of the 64-beam feature stage on one thread (kitti_mini 00, scan 0, launch/sensors/hdl64.yaml's
// 64 rings): which part a speed-up must aim at. Arg: 0 pre-processing, 1 scoring, 2 LOAM selection, 3 LinK3D
// clusters, 4 the sweep thinned to the maps' 0.1 m.
void BM_FeaturePartKitti64Beam(benchmark::State& state) {
  const io::KittiSequence seq = io::KittiSequence::open(std::string(ADIT_SHARED_DATA_DIR) + "/kitti_mini", "00");
  const LidarScan scan = seq.scan(0);
  FeatureConfig cfg;
  cfg.preprocess.num_rings = 64;
  const features::RingCloud rings = features::preprocessScan(scan, cfg.preprocess, nullptr);
  const features::PointScores scores = features::scorePoints(rings, cfg.loam, nullptr);
  const int part = static_cast<int>(state.range(0));
  for (auto _ : state) {
    if (part == 0) benchmark::DoNotOptimize(features::preprocessScan(scan, cfg.preprocess, nullptr));
    if (part == 1) benchmark::DoNotOptimize(features::scorePoints(rings, cfg.loam, nullptr));
    if (part == 2) benchmark::DoNotOptimize(features::selectLoamFeatures(rings, scores, cfg.loam));
    if (part == 3) benchmark::DoNotOptimize(features::extractLinK3dClusters(rings, scores, cfg.link3d));
    if (part == 4) benchmark::DoNotOptimize(features::voxelDownsample(rings.points, 0.1f));
  }
  state.counters["points"] = static_cast<double>(rings.points.size());
}
BENCHMARK(BM_FeaturePartKitti64Beam)->DenseRange(0, 4)->Unit(benchmark::kMicrosecond);

// The feature node's thinning of the deskewed sweep to the maps' 0.1 m (FEATURES' map_cloud).
void BM_MapCloudVoxel16Beam(benchmark::State& state) {
  const FeatureExtractor fx{FeatureConfig{}};
  const FeatureSet f = fx.process(sixteenBeamSweep(), {}, walkingPrior());
  std::size_t kept = 0;
  for (auto _ : state) {
    const std::vector<LidarPoint> thinned = features::voxelDownsample(f.cloud.points, 0.1f);
    kept = thinned.size();
    benchmark::DoNotOptimize(thinned.data());
  }
  state.counters["points"] = static_cast<double>(f.cloud.points.size());
  state.counters["kept"] = static_cast<double>(kept);
}
BENCHMARK(BM_MapCloudVoxel16Beam)->Unit(benchmark::kMicrosecond);

// Matching + RANSAC between two consecutive KITTI sweeps (what odometry adds per sweep for its seed).
void BM_LinK3dMatchAndRansacKitti(benchmark::State& state) {
  const io::KittiSequence seq = io::KittiSequence::open(std::string(ADIT_SHARED_DATA_DIR) + "/kitti_mini", "00");
  const FeatureExtractor fx{FeatureConfig{}};
  const FeatureSet a = fx.process(seq.scan(0), {}, MotionPrior{}), b = fx.process(seq.scan(1), {}, MotionPrior{});
  for (auto _ : state) {
    const auto matches = matchLinK3d(a, b, fx.config().link3d);
    benchmark::DoNotOptimize(estimateTransformRansac(a.keypoints, b.keypoints, matches, fx.config().ransac));
  }
  state.counters["keypoints"] = static_cast<double>(a.keypoints.size());
}
BENCHMARK(BM_LinK3dMatchAndRansacKitti)->Unit(benchmark::kMillisecond);

}  // namespace
}  // namespace adit

BENCHMARK_MAIN();
