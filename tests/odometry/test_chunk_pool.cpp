// The correspondence search (core/chunk_pool.*, registration/parallel_matching.hpp, match_reuse.hpp): every query
// is searched once, an error in a chunk reaches the caller, odometry and mapping give the same bytes with one
// thread or several, and a match is kept across rounds exactly while its query stays within the tolerance.
#include "mapping/scan_to_map.hpp"
#include "odometry/scan_to_scan.hpp"
#include "core/chunk_pool.hpp"
#include "core/thread_cpu.hpp"
#include "registration/match_reuse.hpp"
#include "registration/parallel_matching.hpp"
#include "synthetic_world.hpp"

#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <cstring>
#include <limits>
#include <optional>
#include <stdexcept>
#include <thread>

namespace adit {
namespace {

TEST(ChunkPool, RunsEveryIndexOnceInItsChunk) {
  ChunkPool pool(3);
  for (std::size_t n : {0u, 1u, 7u, 1000u}) {
    std::vector<std::atomic<int>> seen(n);
    std::vector<int> chunk_of(n, -1);
    pool.run(n, 5, [&](int chunk, std::size_t begin, std::size_t end) {
      for (std::size_t i = begin; i < end; ++i) {
        ++seen[i];
        chunk_of[i] = chunk;
      }
    });
    for (std::size_t i = 0; i < n; ++i) {
      EXPECT_EQ(seen[i].load(), 1) << "n " << n << " index " << i;
      const auto [begin, end] = ChunkPool::range(n, 5, chunk_of[i]);
      EXPECT_TRUE(begin <= i && i < end) << "chunks are fixed ranges";
    }
    if (n == 1000) {
      EXPECT_EQ(ChunkPool::range(n, 5, 4), std::make_pair(std::size_t{800}, std::size_t{1000}));
    }
  }
}

TEST(ChunkPool, AnErrorInAChunkReachesTheCallerAndThePoolGoesOn) {
  ChunkPool pool(2);
  EXPECT_THROW(pool.run(100, 8, [](int chunk, std::size_t, std::size_t) {
                 if (chunk == 5) throw std::runtime_error("chunk 5");
               }),
               std::runtime_error);
  std::atomic<std::size_t> sum{0};
  pool.run(100, 8, [&](int, std::size_t begin, std::size_t end) {
    for (std::size_t i = begin; i < end; ++i) sum += i;
  });
  EXPECT_EQ(sum.load(), 4950u);
}

// What the workers spend is counted (STATUS helper_cpu_ms), what the caller spends is not: the caller's chunk
// waits until the other has started on the worker, which burns ~20 ms of its thread's CPU there.
TEST(ChunkPool, CountsTheWorkersCpuTimeOnly) {
  ChunkPool alone(1), pool(2);
  const auto burn = [](double ms) {
    const double until = threadCpuMs() + ms;
    volatile double x = 0;
    while (threadCpuMs() < until) x = x + 1;
  };
  alone.run(2, 2, [&](int, std::size_t, std::size_t) { burn(5); });
  EXPECT_EQ(alone.workerCpuMs(), 0.0);
  const std::thread::id caller = std::this_thread::get_id();
  std::atomic<bool> worker_started{false};
  pool.run(2, 2, [&](int, std::size_t, std::size_t) {
    if (std::this_thread::get_id() != caller) {
      worker_started = true;
      burn(20);
    }
    while (!worker_started) std::this_thread::yield();
  });
  // The worker adds its share just after its last chunk: allow it a moment.
  for (int i = 0; i < 2000 && pool.workerCpuMs() < 19.0; ++i) std::this_thread::sleep_for(std::chrono::milliseconds(1));
  EXPECT_GE(pool.workerCpuMs(), 19.0);
  EXPECT_LT(pool.workerCpuMs(), 1000.0);
}

TEST(ParallelMatching, JoinsChunksInQueryOrder) {
  ChunkPool pool(2);
  // Every third line query and every other plane query match; the point records the query index.
  const auto line = [](std::size_t i, std::vector<LineMatch>& out) {
    if (i % 3 == 0) out.push_back({Eigen::Vector3d(double(i), 0, 0), Eigen::Vector3d::Zero(), Eigen::Vector3d::UnitX()});
  };
  const auto plane = [](std::size_t i, std::vector<PlaneMatch>& out) {
    if (i % 2 == 0) out.push_back({Eigen::Vector3d(double(i), 0, 0), Eigen::Vector3d::UnitZ(), 0.0});
  };
  const Correspondences serial = matchInChunks(nullptr, 300, 500, line, plane);
  const Correspondences parallel = matchInChunks(&pool, 300, 500, line, plane);
  ASSERT_EQ(serial.lines.size(), 100u);
  ASSERT_EQ(serial.planes.size(), 250u);
  ASSERT_EQ(parallel.lines.size(), serial.lines.size());
  ASSERT_EQ(parallel.planes.size(), serial.planes.size());
  for (std::size_t i = 0; i < serial.lines.size(); ++i) EXPECT_EQ(parallel.lines[i].point, serial.lines[i].point);
  for (std::size_t i = 0; i < serial.planes.size(); ++i) EXPECT_EQ(parallel.planes[i].point, serial.planes[i].point);
}

TEST(MatchReuse, KeepsAMatchWhileItsQueryStaysWithinTheTolerance) {
  MatchReuse reuse(1, 1, 0.02);
  int searches = 0;
  // The plane found depends on where the query was searched: its offset records that position's x.
  const auto search = [&](const Eigen::Vector3d& q) -> std::optional<PlaneMatch> {
    ++searches;
    return PlaneMatch{Eigen::Vector3d::Zero(), Eigen::Vector3d::UnitX(), -q.x()};
  };
  std::vector<PlaneMatch> out;
  reuse.add(0, Eigen::Vector3d(1, 0, 0), out, search);
  reuse.add(0, Eigen::Vector3d(1.019, 0, 0), out, search);  // moved 19 mm: kept
  reuse.add(0, Eigen::Vector3d(1.0, 0.015, 0.0), out, search);  // measured from where it was searched: kept
  reuse.add(0, Eigen::Vector3d(1.021, 0, 0), out, search);  // 21 mm: searched again
  reuse.add(0, Eigen::Vector3d(1.03, 0, 0), out, search);   // 9 mm from the new search: kept
  ASSERT_EQ(out.size(), 5u);
  EXPECT_EQ(searches, 2);
  EXPECT_EQ(out[0].offset, -1.0);
  EXPECT_EQ(out[1].offset, -1.0);
  EXPECT_EQ(out[2].offset, -1.0);
  EXPECT_EQ(out[3].offset, -1.021);
  EXPECT_EQ(out[4].offset, -1.021);
  EXPECT_EQ(reuse.searched(), 2u);
  EXPECT_EQ(reuse.reused(), 3u);
}

TEST(MatchReuse, RemembersThatAQueryFoundNothingAndKeepsQueriesApart) {
  MatchReuse reuse(2, 0, 0.05);
  int searches = 0;
  const auto none = [&](const Eigen::Vector3d&) -> std::optional<LineMatch> { ++searches; return std::nullopt; };
  const auto found = [&](const Eigen::Vector3d& q) -> std::optional<LineMatch> {
    ++searches;
    return LineMatch{q, q, Eigen::Vector3d::UnitZ()};
  };
  std::vector<LineMatch> out;
  reuse.add(0, Eigen::Vector3d::Zero(), out, none);
  reuse.add(1, Eigen::Vector3d::Zero(), out, found);  // another query at the same place: its own search
  reuse.add(0, Eigen::Vector3d(0.01, 0, 0), out, found);  // still "nothing": not searched again
  EXPECT_EQ(searches, 2);
  ASSERT_EQ(out.size(), 1u);
  reuse.add(0, Eigen::Vector3d(0.06, 0, 0), out, found);  // moved away: searched, and now it matches
  EXPECT_EQ(searches, 3);
  EXPECT_EQ(out.size(), 2u);
}

TEST(MatchReuse, ZeroToleranceSearchesEveryTimeAndNonFiniteQueriesAreSearched) {
  MatchReuse reuse(0, 1, 0.0);
  int searches = 0;
  const auto search = [&](const Eigen::Vector3d&) -> std::optional<PlaneMatch> { ++searches; return std::nullopt; };
  std::vector<PlaneMatch> out;
  for (int i = 0; i < 3; ++i) reuse.add(0, Eigen::Vector3d(1, 2, 3), out, search);
  EXPECT_EQ(searches, 3);
  MatchReuse nan(0, 1, 1.0);
  const Eigen::Vector3d bad = Eigen::Vector3d::Constant(std::numeric_limits<double>::quiet_NaN());
  for (int i = 0; i < 2; ++i) nan.add(0, bad, out, search);
  EXPECT_EQ(searches, 5) << "a NaN position is never 'within the tolerance'";
}

// A short drive through the box room, odometry then mapping, with `threads` search threads.
std::pair<PoseEstimate, PoseEstimate> drive(int threads, double reuse_m = 0.02) {
  const auto world = test::boxRoom();
  ScanToScanConfig oc;
  oc.registration.search_threads = threads;
  oc.registration.reuse_match_distance_m = reuse_m;
  MapperConfig mc;
  mc.registration.search_threads = threads;
  mc.registration.reuse_match_distance_m = reuse_m;
  ScanToScanOdometry odom(oc);
  ScanToMapMapper mapper(mc);
  const Eigen::Isometry3d motion = test::poseFrom(0.3, -0.1, 0.02, 0.01, -0.005, 0.04);
  Eigen::Isometry3d truth = test::poseFrom(0.5, -0.3, 0.2, 0.0, 0.0, 0.3);
  std::pair<PoseEstimate, PoseEstimate> last;
  for (int i = 0; i < 5; ++i, truth = truth * motion) {
    const FeatureSet f = test::simulateSweep(world, truth, {}, i * 100000, 11 + i);
    last.first = odom.process(f);
    last.second = mapper.process(f, last.first);
  }
  return last;
}

bool sameBytes(const PoseEstimate& a, const PoseEstimate& b) {
  return std::memcmp(a.pose.data(), b.pose.data(), sizeof(double) * 16) == 0 &&
         std::memcmp(a.covariance.data(), b.covariance.data(), sizeof(double) * 36) == 0;
}

TEST(ParallelMatching, OdometryAndMappingGiveTheSameBytesForAnyThreadCount) {
  const auto one = drive(1);
  EXPECT_EQ(one.first.flags & PoseEstimate::kRegistrationFailed, 0);
  EXPECT_EQ(one.second.flags & PoseEstimate::kRegistrationFailed, 0);
  for (int threads : {2, 3}) {
    const auto many = drive(threads);
    EXPECT_TRUE(sameBytes(one.first, many.first)) << threads << " threads, odometry";
    EXPECT_TRUE(sameBytes(one.second, many.second)) << threads << " threads, mapping";
  }
}

// With search threads, each sweep's index is built on the odometry's builder thread while the caller goes
// on. A reset, or the end of the object, with a build in flight leaves that build to finish unused: the reset
// odometry gives what a new one gives, byte for byte.
TEST(ParallelMatching, AResetOdometryDropsTheBuildInFlight) {
  const auto world = test::boxRoom();
  ScanToScanConfig oc;
  oc.registration.search_threads = 2;
  const Eigen::Isometry3d motion = test::poseFrom(0.3, -0.1, 0.02, 0.01, -0.005, 0.04);
  std::vector<FeatureSet> sweeps;
  Eigen::Isometry3d truth = test::poseFrom(0.5, -0.3, 0.2, 0.0, 0.0, 0.3);
  for (int i = 0; i < 4; ++i, truth = truth * motion) sweeps.push_back(test::simulateSweep(world, truth, {}, i * 100000, 21 + i));
  ScanToScanOdometry fresh(oc);
  std::vector<PoseEstimate> expected;
  for (const FeatureSet& f : sweeps) expected.push_back(fresh.process(f));
  ScanToScanOdometry odom(oc);
  odom.process(sweeps[0]);
  odom.process(sweeps[1]);  // its index is being built
  odom.reset();
  for (std::size_t i = 0; i < sweeps.size(); ++i) EXPECT_TRUE(sameBytes(expected[i], odom.process(sweeps[i]))) << i;
  EXPECT_GT(odom.helperCpuMs(), 0.0);  // the search threads' and the builder's CPU since the reset
  {
    ScanToScanOdometry short_lived(oc);
    short_lived.process(sweeps[0]);
  }  // destroyed with its build in flight
}

TEST(MatchReuse, OdometryAndMappingLandWhereSearchingEveryRoundLands) {
  // The pose of the last sweep, with matches kept across rounds and with every round searched afresh:
  // the same to well under the 0.05 m point noise of the synthetic sweeps.
  const auto kept = drive(1, 0.02), fresh = drive(1, 0.0);
  for (const auto& [a, b] : {std::make_pair(kept.first, fresh.first), std::make_pair(kept.second, fresh.second)}) {
    EXPECT_EQ(a.flags & PoseEstimate::kRegistrationFailed, 0);
    EXPECT_LT((a.pose.translation() - b.pose.translation()).norm(), 0.005);
    EXPECT_LT(Eigen::AngleAxisd(a.pose.linear().transpose() * b.pose.linear()).angle(), 0.001);
  }
}

}  // namespace
}  // namespace adit
