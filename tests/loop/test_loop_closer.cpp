// The loop-closer stage on simulated 16-beam sweeps: a drifting lap of a roadway block (true loops closed,
// ATE halved), a periodic roadway (aliasing rejected), and the degeneracy check of the verifier.
#include "box_world.hpp"
#include "loop/loop_closer.hpp"
#include "loop/voxel_filter.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <random>

using namespace adit;
using adit::testing::BoxWorld;
using adit::testing::poseXYYaw;
using adit::testing::simulateSweep;

namespace {

constexpr double kDeg = M_PI / 180.0;

// A 5 m roadway around a 30 x 30 m block of rock (centre line: a 35 m square), with equipment on the walls.
BoxWorld blockLoop() {
  BoxWorld w;
  w.addFloorAndRoof(-10, -10, 50, 50, 4.0);
  w.add(5, 5, 0, 35, 35, 4);       // the block
  w.add(-3, -3, 0, 43, 0, 4);      // outer walls
  w.add(-3, 40, 0, 43, 43, 4);
  w.add(-3, -3, 0, 0, 43, 4);
  w.add(40, -3, 0, 43, 43, 4);
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  for (int i = 0; i < 40; ++i) {  // boxes against the walls, on all four sides
    const double s = 2 + 36 * u(rng), len = 0.6 + 2 * u(rng), d = 0.3 + 0.8 * u(rng), z = 0.8 + 2.7 * u(rng);
    switch (i % 8) {
      case 0: w.add(s, 0, 0, s + len, d, z); break;
      case 1: w.add(s, 5 - d, 0, s + len, 5, z); break;
      case 2: w.add(40 - d, s, 0, 40, s + len, z); break;
      case 3: w.add(35, s, 0, 35 + d, s + len, z); break;
      case 4: w.add(s, 40 - d, 0, s + len, 40, z); break;
      case 5: w.add(s, 35, 0, s + len, 35 + d, z); break;
      case 6: w.add(0, s, 0, d, s + len, z); break;
      default: w.add(5 - d, s, 0, 5, s + len, z); break;
    }
  }
  return w;
}

// True poses every 1 m along the block's centre line, `laps` times plus `extra` metres.
std::vector<Eigen::Isometry3d> lapPoses(int metres) {
  std::vector<Eigen::Isometry3d> out;
  double x = 2.5, y = 2.5, yaw = 0.0;
  for (int k = 0; k < metres; ++k) {
    out.push_back(poseXYYaw(x, y, 1.8, yaw));
    const double nx = x + std::cos(yaw), ny = y + std::sin(yaw);
    if (nx > 37.6 || nx < 2.4 || ny > 37.6 || ny < 2.4) yaw += M_PI / 2;  // corner: turn left
    x += std::round(std::cos(yaw)) * 1.0;
    y += std::round(std::sin(yaw)) * 1.0;
  }
  return out;
}

// Mapper poses: the true steps with a heading drift per metre.
std::vector<Eigen::Isometry3d> drifted(const std::vector<Eigen::Isometry3d>& truth, double yaw_drift_per_step) {
  std::vector<Eigen::Isometry3d> out{truth[0]};
  for (std::size_t k = 1; k < truth.size(); ++k) {
    Eigen::Isometry3d step = truth[k - 1].inverse() * truth[k];
    step.linear() = step.linear() * Eigen::AngleAxisd(yaw_drift_per_step, Eigen::Vector3d::UnitZ()).toRotationMatrix();
    out.push_back(out.back() * step);
  }
  return out;
}

// The mapped poses stamped as drive() feeds them: sweep k at k seconds.
Trajectory stampedAsDriven(const std::vector<Eigen::Isometry3d>& mapped) {
  Trajectory out;
  for (std::size_t k = 0; k < mapped.size(); ++k) out.push_back({static_cast<std::int64_t>(k) * 1000000, mapped[k]});
  return out;
}

std::vector<Eigen::Isometry3d> correctedPoses(const LoopCloser& closer, const Trajectory& uncorrected) {
  std::vector<Eigen::Isometry3d> out;
  for (const StampedPose& p : closer.correctedTrajectory(uncorrected)) out.push_back(p.pose);
  return out;
}

double ate(const std::vector<Eigen::Isometry3d>& estimate, const std::vector<Eigen::Isometry3d>& truth) {
  double sum = 0;
  for (std::size_t k = 0; k < truth.size(); ++k) sum += (estimate[k].translation() - truth[k].translation()).squaredNorm();
  return std::sqrt(sum / static_cast<double>(truth.size()));
}

LoopCloserConfig testConfig() {
  LoopCloserConfig c;
  c.keyframe_distance = 0.9;  // the simulated sweeps are exactly 1 m apart: one keyframe each
  return c;
}

// The corrected trajectory of `closer` against that of the same drive keeping everything: at most 20 % or 5 cm
// worse. Returns its ATE.
double expectAsGoodAsKeepingAll(const LoopCloser& closer, const LoopCloser& keeping_all,
                                const std::vector<Eigen::Isometry3d>& mapped,
                                const std::vector<Eigen::Isometry3d>& truth, const char* what) {
  const Trajectory uncorrected = stampedAsDriven(mapped);
  const double mine = ate(correctedPoses(closer, uncorrected), truth);
  const double all = ate(correctedPoses(keeping_all, uncorrected), truth);
  std::printf("ATE %.3f m uncorrected, %.3f m keeping everything, %.3f m %s\n", ate(mapped, truth), all, mine, what);
  EXPECT_LE(mine, std::max(1.2 * all, all + 0.05)) << what;
  return mine;
}

struct Drive {
  LoopCloser closer{testConfig()};
  int false_loops = 0;
  std::vector<std::pair<int, int>> applied;  // (sweep at which a loop was applied, its query keyframe)
};

void drive(Drive& run, const BoxWorld& world, const std::vector<Eigen::Isometry3d>& truth,
           const std::vector<Eigen::Isometry3d>& mapped) {
  for (std::size_t k = 0; k < truth.size(); ++k) {
    PoseEstimate pe;
    pe.utime = static_cast<std::int64_t>(k) * 1000000;  // 1 m/s, one sweep per keyframe
    pe.pose = mapped[k];
    LidarScan scan = simulateSweep(world, truth[k], static_cast<std::uint32_t>(k + 1), 450);
    scan.utime = pe.utime;
    LoopCloser::Result r = run.closer.process(pe, scan);
    if (k + 1 == truth.size()) {  // end of input: the jobs still in flight
      const LoopCloser::Result last = run.closer.finish();
      r.loops.insert(r.loops.end(), last.loops.begin(), last.loops.end());
    }
    for (const LoopConstraint& loop : r.loops) {
      // Keyframe k is sweep k: its number (seq) indexes the truth whatever was merged out of the graph.
      const auto seq = [&](int index) { return static_cast<std::size_t>(run.closer.keyframes()[static_cast<std::size_t>(index)].seq); };
      run.applied.emplace_back(static_cast<int>(k), static_cast<int>(seq(loop.query_index)));
      const Eigen::Isometry3d T_true = truth[seq(loop.match_index)].inverse() * truth[seq(loop.query_index)];
      // Where the loop measures: a partial loop leaves the roadway's axis to the odometry.
      const double err = measuredPart(loop, (T_true.inverse() * loop.T_match_query).translation()).norm();
      std::printf("loop %zu -> %zu: sc %.3f, rms %.3f m, inliers %.2f, error vs truth %.3f m\n", seq(loop.query_index),
                  seq(loop.match_index), loop.scan_context_distance, loop.fitness, loop.inlier_ratio, err);
      if (err > 0.5) ++run.false_loops;
    }
  }
}

void printStats(const LoopCloserStats& s) {
  std::printf("keyframes %d queries %d candidates %d | rejected: fitness %d degenerate %d odometry %d pairwise %d | "
              "pending %d accepted %d (partial %d)\n",
              s.keyframes, s.queries, s.candidates, s.rejected_fitness, s.rejected_degenerate, s.rejected_odometry,
              s.rejected_pairwise, s.pending, s.accepted, s.partial_loops);
}

}  // namespace

TEST(LoopCloser, ClosesADriftingLapAndHalvesTheError) {
  const BoxWorld world = blockLoop();
  const auto truth = lapPoses(140 + 25);
  const auto mapped = drifted(truth, 0.02 * kDeg);
  Drive run;
  drive(run, world, truth, mapped);
  printStats(run.closer.stats());
  const std::vector<Eigen::Isometry3d> corrected = correctedPoses(run.closer, stampedAsDriven(mapped));
  const double before = ate(mapped, truth), after = ate(corrected, truth);
  std::printf("ATE %.3f m without loop closure, %.3f m with\n", before, after);
  EXPECT_GE(run.closer.stats().accepted, 1);
  EXPECT_EQ(run.false_loops, 0);
  EXPECT_LE(after, 0.5 * before);
  EXPECT_EQ(static_cast<int>(run.closer.keyframes().size()), static_cast<int>(truth.size()));
  EXPECT_GT(run.closer.correctedMap(0.5).size(), 1000u);
}

// Verification and optimisation run on a worker; their outcome is applied loop.apply_delay_s of sensor time
// after the keyframe, whether the worker is a thread or runs inline: the same loops at the same sweeps, the
// same graph to the bit.
TEST(LoopCloser, AppliesLoopJobsAtAFixedLaterSweepWhateverTheThread) {
  const BoxWorld world = blockLoop();
  const auto truth = lapPoses(140 + 25);
  const auto mapped = drifted(truth, 0.02 * kDeg);
  LoopCloserConfig threaded = testConfig(), inline_jobs = testConfig();
  threaded.apply_delay_s = inline_jobs.apply_delay_s = 3.0;  // 3 sweeps of 1 s
  inline_jobs.worker_thread = false;
  Drive a{LoopCloser{threaded}, 0, {}}, b{LoopCloser{inline_jobs}, 0, {}};
  drive(a, world, truth, mapped);
  drive(b, world, truth, mapped);
  ASSERT_FALSE(a.applied.empty());
  EXPECT_EQ(a.applied, b.applied);
  EXPECT_EQ(a.closer.saveState(), b.closer.saveState());
  // A loop is applied 3 s after the keyframe whose job accepted it; a pending loop that joins it is older.
  // (Those still in flight at the end of the input are applied by finish(), at the last sweep.)
  const int last = static_cast<int>(truth.size()) - 1;
  for (const auto& [sweep, query] : a.applied) {
    if (sweep < last) {
      EXPECT_GE(sweep, query + 3) << "applied 3 s after its keyframe";
    }
  }
  EXPECT_TRUE(std::any_of(a.applied.begin(), a.applied.end(), [](const auto& x) { return x.first == x.second + 3; }));
  EXPECT_EQ(a.false_loops, 0);
  // The worker's CPU time (the loop closer's STATUS helper_cpu_ms) counts the jobs it ran; inline jobs count in
  // the caller's.
  EXPECT_GT(a.closer.workerCpuMs(), 0.0);
  EXPECT_EQ(b.closer.workerCpuMs(), 0.0);
}

// A robot that keeps driving a mapped roadway: once a loop ties the second lap to the first, its keyframes keep
// only their graph nodes (loop.revisit_distance), so memory follows the roadway, not the time driven. Loops keep
// closing against the first lap, the trajectory is corrected as well, the map covers the same roadway, and a
// checkpoint restores the revisit keyframes as they were.
TEST(LoopCloser, RevisitedKeyframesKeepOnlyTheirGraphNode) {
  const BoxWorld world = blockLoop();
  const auto truth = lapPoses(140 + 70);
  const auto mapped = drifted(truth, 0.02 * kDeg);
  LoopCloserConfig keep_all = testConfig();
  keep_all.revisit_distance = 0;
  Drive thin{LoopCloser{testConfig()}, 0, {}}, all{LoopCloser{keep_all}, 0, {}};
  drive(thin, world, truth, mapped);
  drive(all, world, truth, mapped);
  printStats(thin.closer.stats());
  const auto& keyframes = thin.closer.keyframes();
  std::size_t first_lap_points = 0, later_points = 0;
  for (std::size_t k = 0; k < keyframes.size(); ++k) (k < 140 ? first_lap_points : later_points) += thin.closer.keyframeCloud(static_cast<int>(k)).size();
  const int revisits = thin.closer.stats().revisit_keyframes;
  std::printf("revisit keyframes %d of %zu; cloud points: first lap %zu, after it %zu\n", revisits, keyframes.size(),
              first_lap_points, later_points);
  EXPECT_EQ(all.closer.stats().revisit_keyframes, 0);
  EXPECT_GE(revisits, 40) << "most of the 70 keyframes after the first lap revisit it";
  EXPECT_LT(later_points, first_lap_points / 4);
  for (std::size_t k = 0; k < 140; ++k) EXPECT_FALSE(thin.closer.clouds().empty(static_cast<int>(k))) << "first lap keyframe " << k;
  // Loops still close (against the first lap), none false, and the correction is as good as keeping everything.
  EXPECT_GE(thin.closer.stats().accepted, 3);
  EXPECT_EQ(thin.false_loops, 0);
  expectAsGoodAsKeepingAll(thin.closer, all.closer, mapped, truth, "with revisits thinned");
  // The map: the same roadway from fewer clouds (0.5 m voxels occupied by one and not the other: < 10 %).
  const auto map_thin = thin.closer.correctedMap(0.5), map_all = all.closer.correctedMap(0.5);
  std::printf("map voxels: %zu with revisits thinned, %zu keeping every cloud\n", map_thin.size(), map_all.size());
  EXPECT_GT(map_thin.size(), 0.9 * static_cast<double>(map_all.size()));
  // A checkpoint keeps them: the restored closer has the same state and counts.
  std::vector<std::string> records;
  for (int k = 0; k < static_cast<int>(keyframes.size()); ++k) records.push_back(thin.closer.keyframeRecord(k));
  LoopCloser restored{testConfig()};
  ASSERT_TRUE(restored.restoreState(thin.closer.saveState(), records));
  EXPECT_EQ(restored.saveState(), thin.closer.saveState());
  EXPECT_EQ(restored.stats().revisit_keyframes, revisits);
  for (int k = 0; k < static_cast<int>(keyframes.size()); ++k)
    EXPECT_EQ(restored.keyframeRecord(k), records[static_cast<std::size_t>(k)]) << k;

  // Clouds paged to a file (a live process) give the same graph, records and map, from a fraction of the memory.
  Drive paged{LoopCloser{testConfig()}, 0, {}};
  paged.closer.pageKeyframesTo(::testing::TempDir() + "loop_closer_test.clouds", 10);
  drive(paged, world, truth, mapped);
  const KeyframeCloudStore& store = paged.closer.clouds();
  std::printf("paged: %zu clouds in the page file (%llu bytes), %zu kB in memory vs %zu kB unpaged\n",
              store.pagedClouds(), static_cast<unsigned long long>(store.pageFileBytes()), store.residentBytes() / 1024,
              thin.closer.clouds().residentBytes() / 1024);
  EXPECT_EQ(paged.closer.saveState(), thin.closer.saveState());
  for (int k = 0; k < static_cast<int>(keyframes.size()); ++k)
    EXPECT_EQ(paged.closer.keyframeRecord(k), records[static_cast<std::size_t>(k)]) << k;
  EXPECT_EQ(paged.closer.correctedMap(0.5), map_thin);
  EXPECT_GE(store.pagedClouds(), 120u);
  EXPECT_LT(store.residentBytes(), thin.closer.clouds().residentBytes() / 5);
  EXPECT_EQ(store.readErrors(), 0u);
  EXPECT_EQ(store.pageErrors(), 0u);
  // Their Scan Contexts too: only the ring keys stay, and a candidate's descriptor read back ranks the same.
  const ScanContextDatabase& contexts = paged.closer.contexts();
  std::printf("paged: %zu Scan Contexts in their page file, %zu kB in memory vs %zu kB unpaged\n",
              contexts.pagedContexts(), contexts.residentBytes() / 1024, thin.closer.contexts().residentBytes() / 1024);
  EXPECT_GE(contexts.pagedContexts(), 100u);
  EXPECT_LT(contexts.residentBytes(), thin.closer.contexts().residentBytes() / 3);
  EXPECT_EQ(contexts.readErrors(), 0u);
  EXPECT_EQ(contexts.pageErrors(), 0u);
  EXPECT_EQ(paged.closer.stats().accepted, thin.closer.stats().accepted);
}

// A patrol: the block driven three times. Once the second lap revisits the first, its keyframes keep only a
// graph node, and those older than loop.retire_after_keyframes are merged out of the graph: the graph follows
// the roadway, not the time driven. Loops keep closing on the third lap, the corrected trajectory is as good as
// with every node kept (the merged keyframes keep their corrections), and a checkpoint taken after merging
// restores to the same state and goes on exactly as the closer that wrote it.
TEST(LoopCloser, APatrolMergesItsRevisitsOutOfTheGraph) {
  const BoxWorld world = blockLoop();
  const auto truth = lapPoses(3 * 140 + 10);
  const auto mapped = drifted(truth, 0.02 * kDeg);
  LoopCloserConfig merging = testConfig(), keep_all = testConfig();
  merging.retire_after_keyframes = 60;
  merging.retire_batch = 20;
  keep_all.retire_after_keyframes = 0;
  Drive merged{LoopCloser{merging}, 0, {}}, all{LoopCloser{keep_all}, 0, {}};
  drive(merged, world, truth, mapped);
  drive(all, world, truth, mapped);
  printStats(merged.closer.stats());
  const LoopCloserStats& s = merged.closer.stats();
  const int in_graph = merged.closer.graph().size();
  std::printf("keyframes %d: %d in the graph, %d merged out (%d revisits); every node kept: %d\n", s.keyframes,
              in_graph, s.retired_keyframes, s.revisit_keyframes, all.closer.graph().size());
  EXPECT_EQ(all.closer.stats().retired_keyframes, 0);
  EXPECT_EQ(in_graph, static_cast<int>(merged.closer.keyframes().size()));
  EXPECT_EQ(in_graph + s.retired_keyframes, s.keyframes);
  EXPECT_GE(s.retired_keyframes, 150) << "most of laps two and three";
  EXPECT_LE(in_graph, 140 + 60 + 20 + 40) << "the first lap, the recent window, a batch, a few kept later";
  EXPECT_EQ(merged.false_loops, 0);
  EXPECT_TRUE(std::any_of(merged.applied.begin(), merged.applied.end(), [](const auto& a) { return a.second >= 300; }))
      << "loops close on the third lap";

  const double ate_merged = expectAsGoodAsKeepingAll(merged.closer, all.closer, mapped, truth, "merging revisits out");
  EXPECT_LE(ate_merged, 0.5 * ate(mapped, truth));

  // Checkpoint after merging: the keyframe log holds a record per keyframe made (merged out or not). Loop jobs
  // applied in the sweep that posts them, so that none is in flight at the checkpoint (a restart loses those).
  LoopCloserConfig same_sweep = merging;
  same_sweep.apply_delay_s = 0;
  LoopCloser live{same_sweep}, restored{same_sweep};
  std::vector<std::string> records;
  const std::size_t split = 330;
  for (std::size_t k = 0; k < truth.size(); ++k) {
    PoseEstimate pe;
    pe.utime = static_cast<std::int64_t>(k) * 1000000;
    pe.pose = mapped[k];
    LidarScan scan = simulateSweep(world, truth[k], static_cast<std::uint32_t>(k + 1), 450);
    scan.utime = pe.utime;
    live.process(pe, scan);
    if (live.stats().keyframes > static_cast<int>(records.size()))
      records.push_back(live.keyframeRecord(static_cast<int>(live.keyframes().size()) - 1));
    if (k == split) {
      ASSERT_GT(live.stats().retired_keyframes, 0);
      ASSERT_TRUE(restored.restoreState(live.saveState(), records));
      EXPECT_TRUE(restored.saveState() == live.saveState());
      const auto restored_poses = correctedPoses(restored, stampedAsDriven(mapped));
      const auto live_poses = correctedPoses(live, stampedAsDriven(mapped));
      for (std::size_t i = 0; i < live_poses.size(); ++i)
        EXPECT_TRUE(restored_poses[i].matrix() == live_poses[i].matrix()) << "merged keyframes' corrections, sweep " << i;
      // A log that lacks a record the state names is refused, and leaves the closer as it was.
      LoopCloser refused{same_sweep};
      EXPECT_FALSE(refused.restoreState(live.saveState(), {records.begin(), records.end() - 1}));
      EXPECT_TRUE(refused.keyframes().empty());
    } else if (k > split) {
      restored.process(pe, scan);
    }
  }
  live.finish();
  restored.finish();
  EXPECT_TRUE(restored.saveState() == live.saveState());
  EXPECT_GT(live.stats().accepted, 0);
}

TEST(LoopCloser, RejectsAPeriodicRoadway) {
  // A straight roadway whose equipment repeats exactly every 60 m: a place 60 m back looks identical.
  const BoxWorld world = adit::testing::makePeriodicRoadway(9, 60.0, 16, 2.4, -3, 4);
  std::vector<Eigen::Isometry3d> truth;
  for (int k = 0; k < 130; ++k) truth.push_back(poseXYYaw(k, 0.1 * std::sin(0.3 * k), 1.8, 0.0));
  Drive run;
  drive(run, world, truth, drifted(truth, 0.01 * kDeg));
  printStats(run.closer.stats());
  EXPECT_EQ(run.closer.stats().accepted, 0);
  EXPECT_EQ(run.false_loops, 0);
  // The aliased places were proposed and fitted, and the odometry gate is what stopped them.
  EXPECT_GT(run.closer.stats().rejected_odometry, 0);
}

// A smooth straight roadway driven out and back: every revisit fit slides along the axis. Partial loops pin
// what the fits do observe (the heading drift's lateral error), never the position along the roadway.
TEST(LoopCloser, PartialLoopsCorrectTheCrossSectionOfAFeaturelessRoadway) {
  BoxWorld world;
  world.addFloorAndRoof(-300, -10, 400, 10, 4.0);
  world.add(-300, 2.4, 0, 400, 4.4, 4);
  world.add(-300, -4.4, 0, 400, -2.4, 4);
  std::vector<Eigen::Isometry3d> truth;
  for (int k = 0; k < 90; ++k) truth.push_back(poseXYYaw(k, 0.0, 1.8, 0.0));
  for (int k = 89; k >= 0; --k) truth.push_back(poseXYYaw(k, 0.0, 1.8, M_PI));
  const auto mapped = drifted(truth, 0.03 * kDeg);
  Drive run;
  drive(run, world, truth, mapped);
  printStats(run.closer.stats());
  const Trajectory uncorrected = stampedAsDriven(mapped);
  const Trajectory corrected = run.closer.correctedTrajectory(uncorrected);
  double before = 0, after = 0;  // worst lateral error over the way back
  for (std::size_t k = 90; k < truth.size(); ++k) {
    before = std::max(before, std::abs(mapped[k].translation().y() - truth[k].translation().y()));
    after = std::max(after, std::abs(corrected[k].pose.translation().y() - truth[k].translation().y()));
  }
  std::printf("worst lateral error on the way back: %.3f m without loop closure, %.3f m with\n", before, after);
  EXPECT_GE(run.closer.stats().accepted, 2);
  EXPECT_EQ(run.closer.stats().partial_loops, run.closer.stats().accepted);
  EXPECT_EQ(run.false_loops, 0);
  EXPECT_LE(after, 0.5 * before);

  LoopCloserConfig off = testConfig();
  off.partial_loops = false;
  Drive refused{LoopCloser(off), 0, {}};
  drive(refused, world, truth, mapped);
  EXPECT_EQ(refused.closer.stats().accepted, 0);
  EXPECT_GT(refused.closer.stats().rejected_degenerate, 0);
}

// Point-to-plane information of surface samples: each point p with normal n adds J^T J, J = [n, p x n].
Matrix6d planeInformation(const std::vector<std::pair<Eigen::Vector3d, Eigen::Vector3d>>& samples) {
  Matrix6d H = Matrix6d::Zero();
  for (const auto& [p, n] : samples) {
    Eigen::Matrix<double, 6, 1> J;
    J << n, p.cross(n);
    H += J * J.transpose();
  }
  return H;
}

// A smooth straight roadway 4.5 m wide along x: floor 1.8 m below the sensor, walls at +-2.25 m, a flat roof.
std::vector<std::pair<Eigen::Vector3d, Eigen::Vector3d>> smoothRoadway() {
  std::vector<std::pair<Eigen::Vector3d, Eigen::Vector3d>> s;
  for (double x = -10; x <= 10; x += 0.25)
    for (double u = -2.0; u <= 2.0; u += 0.25) {
      s.push_back({{x, u, -1.8}, Eigen::Vector3d::UnitZ()});
      s.push_back({{x, u, 1.2}, -Eigen::Vector3d::UnitZ()});
      s.push_back({{x, 2.25, u / 1.4}, -Eigen::Vector3d::UnitY()});
      s.push_back({{x, -2.25, u / 1.4}, Eigen::Vector3d::UnitY()});
    }
  return s;
}

TEST(FitObservability, RoadwayAxisIsFreeButItsRollIsPinned) {
  const FitObservability pinned = analyseFit(planeInformation(smoothRoadway()), 0.02);
  std::printf("smooth roadway: weakest translation ratio %.2e along (%.2f %.2f %.2f), rotation sigma %.2e rad\n",
              pinned.weakestTranslationRatio(), pinned.weakestTranslation().x(), pinned.weakestTranslation().y(),
              pinned.weakestTranslation().z(), pinned.rotation_sigma_rad);
  EXPECT_LT(pinned.weakestTranslationRatio(), 1e-6);
  EXPECT_GT(std::abs(pinned.weakestTranslation().x()), 0.999);
  EXPECT_GT(pinned.middleTranslationRatio(), 0.1);
  // Roll about the axis: the floor and walls are 2-3 m from it and pin it far below the verifier's 0.005 rad
  // (a test that scaled rotations as if every point were 10 m away called this roll unconstrained).
  EXPECT_LT(pinned.rotation_sigma_rad, 0.1 * LoopVerifierConfig{}.max_rotation_sigma);

  // A face across the roadway (the end of a drive) pins the axis too.
  auto faced = smoothRoadway();
  for (double y = -2.0; y <= 2.0; y += 0.25)
    for (double z = -1.5; z <= 1.0; z += 0.25) faced.push_back({{10.0, y, z}, -Eigen::Vector3d::UnitX()});
  EXPECT_GT(analyseFit(planeInformation(faced), 0.02).weakestTranslationRatio(), LoopVerifierConfig{}.min_eigenvalue_ratio);
}

TEST(FitObservability, ARoundPipeLeavesItsRollFree) {
  std::vector<std::pair<Eigen::Vector3d, Eigen::Vector3d>> pipe;
  for (double x = -10; x <= 10; x += 0.25)
    for (double a = 0; a < 2 * M_PI; a += 0.1) {
      const Eigen::Vector3d radial(0, std::cos(a), std::sin(a));
      pipe.push_back({Eigen::Vector3d(x, 0, 0) + 2.0 * radial, -radial});
    }
  const FitObservability pinned = analyseFit(planeInformation(pipe), 0.02);
  EXPECT_GT(pinned.rotation_sigma_rad, LoopVerifierConfig{}.max_rotation_sigma);
  EXPECT_LT(pinned.weakestTranslationRatio(), 1e-6);
}

TEST(LoopVerifier, FeaturelessRoadwayIsDegenerateAndEquipmentMakesItObservable) {
  const auto verify = [](const BoxWorld& world) {
    std::vector<SubmapPiece> pieces;
    std::vector<LidarScan> scans;
    for (int j = -5; j <= 5; ++j) scans.push_back(simulateSweep(world, poseXYYaw(j, 0, 1.8, 0), 100 + j));
    std::vector<std::vector<Eigen::Vector3f>> clouds;
    for (const auto& s : scans) clouds.push_back(adit::testing::positions(s));
    for (int j = -5; j <= 5; ++j) pieces.push_back({&clouds[static_cast<std::size_t>(j + 5)], poseXYYaw(j, 0, 0, 0)});
    const LoopVerifierConfig config;
    const auto submap = buildSubmap(pieces, config.submap_voxel);
    const auto query = adit::testing::positions(simulateSweep(world, poseXYYaw(0.3, 0.2, 1.8, 0.05), 7));
    // Seed 0.5 m and 3 deg off.
    const LoopVerification v = verifyLoop(query, submap, {poseXYYaw(-0.2, 0.1, 0, 0.1)}, config);
    std::printf("%s: rms %.3f inliers %.2f weakest translation ratio %.4f, rotation sigma %.5f rad, x error %.3f m\n", toString(v.verdict), v.icp.rms,
                v.icp.inlier_ratio, v.icp.observability.weakestTranslationRatio(), v.icp.observability.rotation_sigma_rad, v.T_match_query.translation().x() - 0.3);
    return v;
  };
  BoxWorld plain;
  plain.addFloorAndRoof(-100, -10, 100, 10, 4.0);
  plain.add(-100, 2.4, 0, 100, 4.4, 4);
  plain.add(-100, -4.4, 0, 100, -2.4, 4);
  EXPECT_EQ(verify(plain).verdict, LoopVerdict::kDegenerate);
  const LoopVerification good = verify(adit::testing::makeRoadway(3, 4.8, 12, true, -100, 100));
  EXPECT_EQ(good.verdict, LoopVerdict::kAccepted);
  EXPECT_NEAR(good.T_match_query.translation().x(), 0.3, 0.05);
  EXPECT_NEAR(good.T_match_query.translation().y(), 0.2, 0.05);
}

TEST(LoopCloser, BadInputNeverCrashes) {
  LoopCloser closer;
  PoseEstimate pe;
  LidarScan empty;
  EXPECT_TRUE(closer.process(pe, empty).keyframe_added);  // first keyframe, even without points
  pe.utime = 1;
  pe.pose.translation().x() = std::nan("");
  EXPECT_FALSE(closer.process(pe, empty).keyframe_added);
  pe.utime = 0;  // out of order
  pe.pose = Eigen::Isometry3d::Identity();
  pe.pose.translation().x() = 5;
  EXPECT_FALSE(closer.process(pe, empty).keyframe_added);
  EXPECT_EQ(closer.stats().invalid_sweeps, 2);
}

TEST(LoopCloser, ConfigReadsDottedKeys) {
  Config c;
  c.set("loop.scan_context.rings", "30");
  c.set("loop.verifier.max_rms", "0.1");
  c.set("loop.min_consistent_loops", "1");
  const LoopCloserConfig k = loopCloserConfigFrom(c);
  EXPECT_EQ(k.scan_context.rings, 30);
  EXPECT_DOUBLE_EQ(k.verifier.max_rms, 0.1);
  EXPECT_EQ(k.min_consistent_loops, 1);
  EXPECT_DOUBLE_EQ(k.keyframe_distance, 1.0);
}

namespace adit {
namespace {

TEST(VoxelAccumulator, SameCentroidsAsDownsamplingAllPointsAtOnce) {
  std::vector<Eigen::Vector3f> points;
  VoxelAccumulator grid(0.3);
  for (int i = 0; i < 20000; ++i) {
    const float t = static_cast<float>(i) * 0.37f;
    points.emplace_back(std::fmod(t, 23.0f) - 11.0f, std::sin(t) * 4.0f, std::cos(t * 0.7f) * 2.0f);
    grid.add(points.back());
  }
  grid.add(Eigen::Vector3f(std::nanf(""), 0.0f, 0.0f));
  EXPECT_EQ(grid.centroids(), voxelDownsample(points, 0.3));
  // Added in batches (the table grows inside them; a NaN among them), the same sums bit for bit.
  std::vector<Eigen::Vector3f> with_nan = points;
  with_nan.insert(with_nan.begin() + 7, Eigen::Vector3f(0.0f, std::nanf(""), 0.0f));
  VoxelAccumulator batched(0.3);
  for (std::size_t begin = 0; begin < with_nan.size(); begin += 6000)
    batched.add(std::vector<Eigen::Vector3f>(with_nan.begin() + static_cast<long>(begin),
                                             with_nan.begin() + static_cast<long>(std::min(begin + 6000, with_nan.size()))));
  EXPECT_GT(batched.size(), 1024u);
  EXPECT_EQ(batched.centroids(), voxelDownsample(points, 0.3));
}

// A corrupt cloud or pose (fuzz_map_bundle: a saved map's neighbour at 1e26 m) must not make the voxel index
// overflow its integer (undefined behaviour): such points have no voxel and are dropped, the rest kept.
TEST(VoxelDownsample, DropsPointsTooFarForAVoxelIndex) {
  const std::vector<Eigen::Vector3f> points = {{1.0f, 2.0f, 3.0f}, {5.5e26f, 0.0f, 0.0f}, {0.0f, -3e38f, 0.0f},
                                               {1.05f, 2.05f, 3.05f}, {0.0f, 0.0f, 1e17f}};
  const std::vector<Eigen::Vector3f> kept = voxelDownsample(points, 0.3);
  // (1, 2, 3) and (1.05, 2.05, 3.05) share a voxel of 0.3 m; 1e17 m is far but its index still fits. In key
  // order: (0, 0, 3.3e17) before (3, 6, 10).
  ASSERT_EQ(kept.size(), 2u);
  EXPECT_NEAR(kept[0].z(), 1e17f, 1e11f);
  EXPECT_TRUE(kept[1].isApprox(Eigen::Vector3f(1.025f, 2.025f, 3.025f), 1e-6f));
  VoxelAccumulator grid(0.3);
  for (const Eigen::Vector3f& p : points) grid.add(p);
  EXPECT_EQ(grid.centroids(), kept);
}

// Clouds near the origin take a packed one-integer voxel key; one point beyond +-2^20 voxels sends the whole
// cloud through the three-integer key. Both must give the same centroids in the same order, bit for bit.
TEST(VoxelDownsample, PackedAndWideKeysGiveTheSameCentroids) {
  std::vector<Eigen::Vector3f> near;
  std::mt19937 rng(3);
  std::uniform_real_distribution<float> coord(-5.0f, 5.0f);
  for (int i = 0; i < 5000; ++i) near.emplace_back(coord(rng), coord(rng), 0.1f * coord(rng));
  const std::vector<Eigen::Vector3f> packed = voxelDownsample(near, 0.25);
  std::vector<Eigen::Vector3f> with_far = near;
  with_far.emplace_back(1e6f, 0.0f, 0.0f);  // voxel 4e6: beyond the packed range, and last in key order
  std::vector<Eigen::Vector3f> wide = voxelDownsample(with_far, 0.25);
  ASSERT_EQ(wide.size(), packed.size() + 1);
  EXPECT_EQ(wide.back(), with_far.back());
  wide.pop_back();
  EXPECT_EQ(wide, packed);
  EXPECT_LT(packed.size(), near.size() * 3 / 4);  // voxels were shared: the sums and their order were exercised
  VoxelAccumulator grid(0.25);  // the accumulator agrees too, with packed keys and without
  for (const Eigen::Vector3f& p : near) grid.add(p);
  EXPECT_EQ(grid.centroids(), packed);
  grid.add(with_far.back());
  wide.push_back(with_far.back());
  EXPECT_EQ(grid.centroids(), wide);
}

}  // namespace
}  // namespace adit
