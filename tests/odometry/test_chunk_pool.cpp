// The parallel correspondence search (registration/chunk_pool.*, parallel_matching.hpp): every query is
// searched once, an error in a chunk reaches the caller, and odometry and mapping give the same bytes with
// one thread or several.
#include "mapping/scan_to_map.hpp"
#include "odometry/scan_to_scan.hpp"
#include "registration/chunk_pool.hpp"
#include "registration/parallel_matching.hpp"
#include "synthetic_world.hpp"

#include <gtest/gtest.h>

#include <atomic>
#include <cstring>
#include <stdexcept>

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

// A short drive through the box room, odometry then mapping, with `threads` search threads.
std::pair<PoseEstimate, PoseEstimate> drive(int threads) {
  const auto world = test::boxRoom();
  ScanToScanConfig oc;
  oc.registration.search_threads = threads;
  MapperConfig mc;
  mc.registration.search_threads = threads;
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

}  // namespace
}  // namespace adit
