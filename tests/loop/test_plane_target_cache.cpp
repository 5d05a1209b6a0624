// The loop jobs' cache of candidate submaps' ICP targets: a target is reused for an equal neighbourhood only
// (the same clouds at bit-for-bit the same poses), evicted least recently used, and a reused target aligns a
// query exactly as a freshly built one.
#include "box_world.hpp"
#include "loop/plane_target_cache.hpp"

#include <gtest/gtest.h>

#include <cmath>

namespace adit {
namespace {

CandidateNeighbourhood neighbourhoodAt(double x) {
  const testing::BoxWorld world = testing::makeRoadway(3, 4.8, 12, true);
  CandidateNeighbourhood n;
  for (int k = -1; k <= 1; ++k) {
    const Eigen::Isometry3d T_match_cloud = testing::poseXYYaw(2.0 * k, 0.0, 0.0, 0.0);
    const LidarScan sweep =
        testing::simulateSweep(world, testing::poseXYYaw(x + 2.0 * k, 0.0, 1.0, 0.0), static_cast<std::uint32_t>(10 + k));
    n.clouds.push_back(CompactCloud::encode(testing::positions(sweep), 0.01f));
    n.T_match_cloud.push_back(T_match_cloud);
  }
  return n;
}

TEST(PlaneTargetCache, ReusesATargetOnlyForTheSameNeighbourhood) {
  const LoopVerifierConfig config;
  PlaneTargetCache cache(4);
  const CandidateNeighbourhood a = neighbourhoodAt(0.0);
  const auto first = cache.target(a, config);
  const auto again = cache.target(a, config);
  EXPECT_EQ(first.get(), again.get());
  EXPECT_EQ(cache.builds(), 1u);
  EXPECT_EQ(cache.hits(), 1u);

  // The same clouds, one pose moved by the last bit (the graph was optimised): another submap.
  CandidateNeighbourhood moved = a;
  moved.T_match_cloud[2].translation().x() = std::nextafter(moved.T_match_cloud[2].translation().x(), 10.0);
  EXPECT_FALSE(sameNeighbourhood(a, moved));
  EXPECT_NE(cache.target(moved, config).get(), first.get());
  // One count of one cloud differs: another submap.
  CandidateNeighbourhood recounted = a;
  std::vector<std::int16_t> counts = recounted.clouds[0].counts();
  counts[4] += 1;
  recounted.clouds[0] = *CompactCloud::fromCounts(recounted.clouds[0].step(), counts);
  EXPECT_FALSE(sameNeighbourhood(a, recounted));
  EXPECT_NE(cache.target(recounted, config).get(), first.get());
  EXPECT_EQ(cache.builds(), 3u);
}

TEST(PlaneTargetCache, EvictsTheLeastRecentlyUsed) {
  const LoopVerifierConfig config;
  PlaneTargetCache cache(2);
  const CandidateNeighbourhood a = neighbourhoodAt(0.0), b = neighbourhoodAt(10.0), c = neighbourhoodAt(20.0);
  cache.target(a, config);
  cache.target(b, config);
  cache.target(a, config);  // a is now the most recent
  cache.target(c, config);  // evicts b
  EXPECT_EQ(cache.builds(), 3u);
  cache.target(a, config);
  EXPECT_EQ(cache.builds(), 3u);
  cache.target(b, config);
  EXPECT_EQ(cache.builds(), 4u);
  cache.clear();
  cache.target(b, config);
  EXPECT_EQ(cache.builds(), 5u);
  PlaneTargetCache none(0);
  none.target(a, config);
  none.target(a, config);
  EXPECT_EQ(none.builds(), 2u);
}

TEST(PlaneTargetCache, AKeptTargetAlignsAsAFreshOne) {
  const LoopVerifierConfig config;
  PlaneTargetCache cache(4);
  const CandidateNeighbourhood n = neighbourhoodAt(0.0);
  cache.target(n, config);
  const auto kept = cache.target(n, config);
  const std::unique_ptr<PlaneTarget> fresh = candidateTarget(n, config);
  const testing::BoxWorld world = testing::makeRoadway(3, 4.8, 12, true);
  const std::vector<Eigen::Vector3f> source =
      querySource(testing::positions(testing::simulateSweep(world, testing::poseXYYaw(0.7, 0.2, 1.0, 0.05), 99)), config);
  const std::vector<Eigen::Isometry3d> seeds{Eigen::Isometry3d::Identity()};
  const LoopVerification a = verifyLoopAgainst(*kept, source, seeds, config);
  const LoopVerification b = verifyLoopAgainst(*fresh, source, seeds, config);
  EXPECT_EQ(a.verdict, b.verdict);
  EXPECT_TRUE(a.T_match_query.isApprox(b.T_match_query, 0.0));
  EXPECT_EQ(a.icp.rms, b.icp.rms);
  EXPECT_EQ(a.verdict, LoopVerdict::kAccepted);  // the query is truly 0.7 m along, 0.2 m across: found
  EXPECT_NEAR(a.T_match_query.translation().x(), 0.7, 0.1);
}

}  // namespace
}  // namespace adit
