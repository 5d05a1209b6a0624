// Loop-closure speed: Scan Context build + candidate search with 5,000 keyframes in the database (target
// <= 2 ms), and optimisation of a 5,000-node pose graph with 20 loops (target < 1 s).
#include "box_world.hpp"
#include "io/kitti.hpp"
#include "loop/compact_cloud.hpp"
#include "loop/loop_verifier.hpp"
#include "loop/pose_graph.hpp"
#include "loop/voxel_filter.hpp"
#include "loop/scan_context_database.hpp"

#include <benchmark/benchmark.h>

#include <cmath>
#include <random>

using namespace adit;

namespace {

// 5,000 keyframe contexts from 50 simulated roadway sweeps, each seen from 100 yaws/offsets.
struct Database {
  ScanContextConfig config;
  ScanContextDatabase db{10, 50};
  std::vector<Eigen::Vector3f> query_points;
  Database() {
    std::mt19937 rng(1);
    std::uniform_real_distribution<float> yaw(-3.1f, 3.1f), off(-0.5f, 0.5f);
    for (int place = 0; place < 50; ++place) {
      const auto world = adit::testing::makeRoadway(static_cast<std::uint32_t>(place), 4.5 + 0.01 * place, 12, place % 4 == 0);
      const auto pts = adit::testing::positions(
          adit::testing::simulateSweep(world, adit::testing::poseXYYaw(0, 0, 1.8, 0), static_cast<std::uint32_t>(place)));
      for (int view = 0; view < 100; ++view) {
        const Eigen::Matrix3f R = Eigen::AngleAxisf(yaw(rng), Eigen::Vector3f::UnitZ()).toRotationMatrix();
        const Eigen::Vector3f t(off(rng), off(rng), 0.0f);
        std::vector<Eigen::Vector3f> moved;
        moved.reserve(pts.size());
        for (const auto& p : pts) moved.push_back(R * p + t);
        db.add(ScanContext::build(moved, config), static_cast<std::int64_t>(db.size()) * 100000);
      }
    }
    query_points = adit::testing::positions(adit::testing::simulateSweep(
        adit::testing::makeRoadway(7, 4.57, 12, false), adit::testing::poseXYYaw(0.3, 0.1, 1.8, 1.0), 99));
  }
};

void BM_ScanContextBuildAndQuery5000(benchmark::State& state) {
  static Database d;
  for (auto _ : state) {
    const ScanContext sc = ScanContext::build(d.query_points, d.config);
    auto candidates = d.db.query(sc, 50);
    benchmark::DoNotOptimize(candidates);
  }
  state.counters["keyframes"] = d.db.size();
  state.counters["points"] = static_cast<double>(d.query_points.size());
}
BENCHMARK(BM_ScanContextBuildAndQuery5000)->Unit(benchmark::kMillisecond);

// A 5,000-node drifting trajectory (1 m steps, slow turns) with 20 loop edges to true relative poses.
PoseGraph graph5000() {
  std::vector<Eigen::Isometry3d> truth{Eigen::Isometry3d::Identity()};
  for (int i = 1; i < 5000; ++i) {
    Eigen::Isometry3d step = Eigen::Isometry3d::Identity();
    step.translation().x() = 1.0;
    step.linear() = Eigen::AngleAxisd(2.0 * M_PI / 250.0, Eigen::Vector3d::UnitZ()).toRotationMatrix();  // laps of 250 m
    truth.push_back(truth.back() * step);
  }
  Matrix6d info = Matrix6d::Identity();
  info.diagonal() << 2500, 2500, 2500, 250000, 250000, 250000;
  PoseGraph g;
  g.addNode(truth[0]);
  for (int i = 1; i < 5000; ++i) {
    Eigen::Isometry3d step = truth[static_cast<std::size_t>(i - 1)].inverse() * truth[static_cast<std::size_t>(i)];
    step.linear() = step.linear() * Eigen::AngleAxisd(0.0005, Eigen::Vector3d::UnitZ()).toRotationMatrix();
    g.addNode(g.pose(i - 1) * step);
    g.addOdometryEdge(i - 1, i, step, info);
  }
  for (int k = 1; k <= 20; ++k) {  // each loop: a node and the same place one lap (250 nodes) earlier
    const int q = 4999 - 240 * (k - 1), m = q - 250;
    g.addLoopEdge(m, q, truth[static_cast<std::size_t>(m)].inverse() * truth[static_cast<std::size_t>(q)], info);
  }
  return g;
}

void BM_PoseGraph5000Nodes20Loops(benchmark::State& state) {
  const PoseGraph initial = graph5000();
  PoseGraphReport report;
  for (auto _ : state) {
    state.PauseTiming();
    PoseGraph g = initial;
    state.ResumeTiming();
    report = g.optimize();
    benchmark::DoNotOptimize(report);
  }
  state.counters["iterations"] = report.iterations;
  state.counters["solved"] = report.solved ? 1 : 0;
}
BENCHMARK(BM_PoseGraph5000Nodes20Loops)->Unit(benchmark::kMillisecond);

// A keyframe's cloud (a simulated 16-beam sweep thinned to 0.2 m) quantised and decoded: what keeping the
// keyframe clouds compact costs per keyframe, and per cloud a loop job decodes.
std::vector<Eigen::Vector3f> keyframeCloud() {
  const auto sweep = adit::testing::positions(adit::testing::simulateSweep(
      adit::testing::makeRoadway(7, 4.57, 12, false), adit::testing::poseXYYaw(0.3, 0.1, 1.8, 1.0), 99));
  return voxelDownsample(sweep, 0.2);
}

void BM_KeyframeCloudEncode(benchmark::State& state) {
  const auto cloud = keyframeCloud();
  for (auto _ : state) benchmark::DoNotOptimize(CompactCloud::encode(cloud, 0.005f));
  state.counters["points"] = static_cast<double>(cloud.size());
}
BENCHMARK(BM_KeyframeCloudEncode)->Unit(benchmark::kMicrosecond);

void BM_KeyframeCloudDecode(benchmark::State& state) {
  const CompactCloud compact = CompactCloud::encode(keyframeCloud(), 0.005f);
  for (auto _ : state) benchmark::DoNotOptimize(compact.decode());
  state.counters["points"] = static_cast<double>(compact.size());
}
BENCHMARK(BM_KeyframeCloudDecode)->Unit(benchmark::kMicrosecond);

// A loop job's two halves (issue 15: the loop closer's worker was 25 % of the 500 s demo drive's CPU). The
// candidate's submap: eleven simulated 16-beam keyframes a metre apart along a roadway, each thinned to the
// keyframes' 0.2 m, merged at the verifier's 0.25 m in the middle one's frame, as a loop job builds it.
std::vector<Eigen::Vector3f> candidateSubmap() {
  const auto world = adit::testing::makeRoadway(7, 4.57, 12, true);
  std::vector<std::vector<Eigen::Vector3f>> clouds;
  for (int k = 0; k < 11; ++k)
    clouds.push_back(voxelDownsample(adit::testing::positions(adit::testing::simulateSweep(
                                         world, adit::testing::poseXYYaw(k - 5.0, 0.1, 1.8, 0.0), 99 + k)),
                                     0.2));
  std::vector<SubmapPiece> pieces;
  for (int k = 0; k < 11; ++k) pieces.push_back({&clouds[static_cast<std::size_t>(k)], adit::testing::poseXYYaw(k - 5.0, 0.0, 0.0, 0.0)});
  return buildSubmap(pieces, LoopVerifierConfig{}.submap_voxel);
}

// The plane target (a normal fitted at every submap point): built once per candidate neighbourhood.
void BM_LoopPlaneTarget(benchmark::State& state) {
  const std::vector<Eigen::Vector3f> submap = candidateSubmap();
  const LoopVerifierConfig config;
  int planar = 0;
  for (auto _ : state) {
    const PlaneTarget target(submap, config.icp);
    planar = target.planarPoints();
    benchmark::DoNotOptimize(planar);
  }
  state.counters["points"] = static_cast<double>(submap.size());
  state.counters["planar"] = planar;
}
BENCHMARK(BM_LoopPlaneTarget)->Unit(benchmark::kMillisecond);

// One ICP of a query keyframe (0.4 m beside the middle one, 0.5 m voxel) from a seed 0.6 m and 3 deg off.
void BM_LoopIcp(benchmark::State& state) {
  const LoopVerifierConfig config;
  const PlaneTarget target(candidateSubmap(), config.icp);
  const auto world = adit::testing::makeRoadway(7, 4.57, 12, true);
  const std::vector<Eigen::Vector3f> query = querySource(
      voxelDownsample(adit::testing::positions(adit::testing::simulateSweep(world, adit::testing::poseXYYaw(0.4, 0.1, 1.8, 0.0), 7)), 0.2),
      config);
  const Eigen::Isometry3d seed = adit::testing::poseXYYaw(1.0, 0.0, 0.0, 3.0 * M_PI / 180.0);
  IcpResult r;
  for (auto _ : state) {
    r = alignPointToPlane(target, query, seed, config.icp);
    benchmark::DoNotOptimize(r.rms);
  }
  state.counters["iterations"] = r.iterations;
  state.counters["error_mm"] = 1e3 * (r.T_target_source.translation() - Eigen::Vector3d(0.4, 0.0, 0.0)).norm();
  state.counters["inlier_ratio"] = r.inlier_ratio;
}
BENCHMARK(BM_LoopIcp)->Unit(benchmark::kMillisecond);

// The corrected map of a run's end (map.pcd): kitti_mini 00's ten HDL-64 scans thinned to the keyframes' 0.2 m,
// each placed ten times along a 100 m drive (one keyframe a metre), accumulated into the 0.1 m grid and read out.
void BM_CorrectedMapOf100Keyframes(benchmark::State& state) {
  const io::KittiSequence seq = io::KittiSequence::open(std::string(ADIT_SHARED_DATA_DIR) + "/kitti_mini", "00");
  std::vector<std::vector<Eigen::Vector3f>> clouds;
  for (std::size_t i = 0; i < seq.size(); ++i) {
    std::vector<Eigen::Vector3f> points;
    for (const LidarPoint& p : seq.scan(i).points) points.push_back(p.p);
    clouds.push_back(voxelDownsample(points, 0.2));
  }
  std::size_t added = 0, voxels = 0;
  for (auto _ : state) {
    VoxelAccumulator grid(0.1);
    added = 0;
    for (int k = 0; k < 100; ++k) {
      const Eigen::Isometry3f T(Eigen::Translation3f(static_cast<float>(k), 0.0f, 0.0f) *
                                Eigen::AngleAxisf(0.01f * static_cast<float>(k), Eigen::Vector3f::UnitZ()));
      std::vector<Eigen::Vector3f> placed;
      for (const Eigen::Vector3f& p : clouds[static_cast<std::size_t>(k) % clouds.size()]) placed.push_back(T * p);
      grid.add(placed);
      added += placed.size();
    }
    const std::vector<Eigen::Vector3f> map = grid.centroids();
    voxels = map.size();
    benchmark::DoNotOptimize(map.data());
  }
  state.counters["points"] = static_cast<double>(added);
  state.counters["voxels"] = static_cast<double>(voxels);
}
BENCHMARK(BM_CorrectedMapOf100Keyframes)->Unit(benchmark::kMillisecond);

}  // namespace

BENCHMARK_MAIN();
