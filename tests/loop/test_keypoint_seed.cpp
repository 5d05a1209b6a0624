// LinK3D keypoints in loop verification: their compact storage, the seed they give a candidate, what the loop
// job does with it (finds a revisit the Scan Context and graph seeds miss, refuses an aliased place), and the
// keyframes' keypoints in checkpoints.
#include "box_world.hpp"
#include "features/feature_extractor.hpp"
#include "loop/keypoint_seed.hpp"
#include "loop/loop_closer.hpp"
#include "loop/loop_job.hpp"
#include "loop/se3.hpp"
#include "loop/voxel_filter.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <random>

using namespace adit;
using adit::testing::BoxWorld;
using adit::testing::poseXYYaw;
using adit::testing::simulateSweep;

namespace {

constexpr double kDeg = M_PI / 180.0;

struct Sweep {
  CompactCloud cloud;
  KeyframeKeypoints keypoints;
};

Sweep sweepAt(const BoxWorld& world, const Eigen::Isometry3d& T_world_lidar, std::uint32_t seed) {
  LidarScan scan = simulateSweep(world, T_world_lidar, seed, 900);
  const FeatureSet f = FeatureExtractor(FeatureConfig{}).process(scan, {}, MotionPrior{});
  Sweep s;
  s.cloud = CompactCloud::encode(voxelDownsample(adit::testing::positions(scan), 0.2), 0.005f);
  s.keypoints = KeyframeKeypoints::encode(f.keypoints, f.descriptors);
  return s;
}

// A candidate keyframe at `match` with keyframes every metre `neighbours` each side along the roadway (x).
struct Neighbourhood {
  CandidateNeighbourhood clouds;
  std::vector<KeyframeKeypointsPtr> keypoints;
};

Neighbourhood neighbourhoodAt(const BoxWorld& world, const Eigen::Isometry3d& match, int neighbours) {
  Neighbourhood n;
  for (int j = -neighbours; j <= neighbours; ++j) {
    const Eigen::Isometry3d pose = match * poseXYYaw(j, 0, 0, 0);
    Sweep s = sweepAt(world, pose, static_cast<std::uint32_t>(100 + j));
    n.clouds.clouds.push_back(std::move(s.cloud));
    n.clouds.T_match_cloud.push_back(match.inverse() * pose);
    n.keypoints.push_back(std::make_shared<const KeyframeKeypoints>(std::move(s.keypoints)));
  }
  return n;
}

double angleDeg(const Eigen::Isometry3d& T) { return Eigen::AngleAxisd(T.linear()).angle() / kDeg; }

// A loop job of query keyframe 1 against candidate keyframe 0 whose graph and Scan Context seeds are both far off:
// the graph puts the query `graph_offset` from where it is, the Scan Context yaw is 90 degrees wrong.
LoopJob jobWithBadSeeds(const Eigen::Isometry3d& match, const Eigen::Isometry3d& query, const Sweep& query_sweep,
                        Neighbourhood n, const Eigen::Isometry3d& graph_offset) {
  LoopJob job;
  job.query = 1;
  job.query_utime = 100'000'000;
  job.query_uncorrected = query * graph_offset;
  job.query_cloud = query_sweep.cloud;
  job.query_keypoints = std::make_shared<const KeyframeKeypoints>(query_sweep.keypoints);
  job.graph.addNode(match);
  job.graph.addNode(query * graph_offset);
  Matrix6d wide = Matrix6d::Identity() * 100.0;  // a long drive between the visits: the gate lets it through
  job.chain.add(match, Matrix6d::Zero());
  job.chain.add(query * graph_offset, wide);
  LoopCandidateSnapshot c;
  c.candidate.index = 0;
  c.candidate.distance = 0.1;
  c.candidate.yaw = M_PI / 2;
  c.match_utime = 0;
  c.match_uncorrected = match;
  c.neighbourhood = std::move(n.clouds);
  c.neighbourhood_keypoints = std::move(n.keypoints);
  job.candidates.push_back(std::move(c));
  return job;
}

// An odometry chain sure of the way between the two visits to 0.5 m (one sigma per axis).
OdometryChain sureChain(const Eigen::Isometry3d& match, const Eigen::Isometry3d& query) {
  OdometryChain chain;
  chain.add(match, Matrix6d::Zero());
  chain.add(query, Matrix6d::Identity() * 0.25);
  return chain;
}

LoopCloserConfig jobConfig(bool keypoints) {
  LoopCloserConfig c;
  c.keypoints.use = keypoints;
  c.min_consistent_loops = 1;  // one job, one loop: judged alone
  return c;
}

}  // namespace

TEST(KeyframeKeypoints, KeepsDescriptorsToHalfACentimetreAndRoundTripsAsBytes) {
  std::mt19937 rng(3);
  std::uniform_real_distribution<float> u(0.0f, 1.0f);
  std::vector<Eigen::Vector3f> points;
  std::vector<LinK3dDescriptor> descriptors;
  for (int i = 0; i < 30; ++i) {
    points.emplace_back(20 * u(rng) - 10, 20 * u(rng) - 10, 3 * u(rng));
    LinK3dDescriptor d{};
    for (float& bin : d) bin = u(rng) < 0.7f ? 0.0f : 40.0f * u(rng);
    descriptors.push_back(d);
  }
  points.emplace_back(std::nanf(""), 0.0f, 0.0f);  // dropped with its descriptor
  descriptors.push_back(descriptors.front());
  const KeyframeKeypoints k = KeyframeKeypoints::encode(points, descriptors);
  ASSERT_EQ(k.size(), 30u);
  const std::vector<LinK3dDescriptor> back = k.descriptors();
  for (std::size_t i = 0; i < 30; ++i)
    for (int b = 0; b < kLinK3dBins; ++b) {
      const float want = descriptors[i][static_cast<std::size_t>(b)] >= 0.005f ? descriptors[i][static_cast<std::size_t>(b)] : 0.0f;
      EXPECT_NEAR(back[i][static_cast<std::size_t>(b)], want, 0.0051f);
    }
  EXPECT_LT(k.bytes(), 30u * (12 + 4 + 3 * 70));  // ~30 % of the bins set: sparse, not 732 bytes a keypoint

  ByteWriter w;
  k.put(w);
  ByteReader r(w.bytes());
  const std::optional<KeyframeKeypoints> read = KeyframeKeypoints::get(r);
  ASSERT_TRUE(read);
  EXPECT_TRUE(r.atEnd());
  EXPECT_EQ(read->points(), k.points());
  EXPECT_EQ(read->descriptors(), back);

  // Truncated anywhere, or a bin out of order / out of range: refused, nothing half-read.
  const std::string bytes = w.bytes();
  for (std::size_t cut : {std::size_t{3}, std::size_t{9}, bytes.size() / 2, bytes.size() - 1}) {
    ByteReader t(bytes.data(), cut);
    EXPECT_FALSE(KeyframeKeypoints::get(t)) << cut;
  }
  std::string bad = bytes;
  bad[8 + 12 + 1] = static_cast<char>(200);  // the first keypoint's first bin: 200 >= 180
  ByteReader b(bad);
  EXPECT_FALSE(KeyframeKeypoints::get(b));
}

TEST(KeypointSeed, FindsARevisitMetresToTheSideFromLinK3dKeypoints) {
  const BoxWorld world = adit::testing::makeRoadway(11, 8.0, 24);
  const Eigen::Isometry3d match = poseXYYaw(0, 0, 1.8, 0);
  // The second visit passes 1.8 m to the side, 0.6 m further along, turned 25 degrees.
  const Eigen::Isometry3d query = poseXYYaw(0.6, 1.8, 1.8, 25 * kDeg);
  const Neighbourhood n = neighbourhoodAt(world, match, 5);
  const Sweep q = sweepAt(world, query, 7);
  const KeypointSeed seed = keypointSeed(q.keypoints, n.keypoints, n.clouds.T_match_cloud, KeypointSeedConfig{});
  const Eigen::Isometry3d error = (match.inverse() * query).inverse() * seed.T_match_query;
  std::printf("query keypoints %zu, matches %d, inliers %d; seed error %.3f m, %.2f deg\n", q.keypoints.size(),
              seed.matches, seed.inliers, error.translation().norm(), angleDeg(error));
  // Within what ICP's coarse phase converges from (the verifier's 1.5 m gate), and within the 1 m / 5 deg at
  // which loop.keypoints calls a seed and a fit the same alignment: cluster centroids move with the viewpoint.
  ASSERT_TRUE(seed.ok);
  EXPECT_LT(error.translation().norm(), 0.3);
  EXPECT_LT(angleDeg(error), 4.0);

  // Another roadway (other equipment): the descriptors match by chance at most, and no seed comes of it.
  const Sweep elsewhere = sweepAt(adit::testing::makeRoadway(12, 8.0, 24), query, 8);
  const KeypointSeed none = keypointSeed(elsewhere.keypoints, n.keypoints, n.clouds.T_match_cloud, KeypointSeedConfig{});
  std::printf("elsewhere: matches %d, inliers %d\n", none.matches, none.inliers);
  EXPECT_FALSE(none.ok);
}

// Loop jobs with the scheduler's cache of submap targets: the same outcome as without it; the second job on
// the same candidate neighbourhood verifies against the kept target and says so (STATUS submaps_reused).
TEST(KeypointSeed, AJobOnAKeptSubmapTargetDecidesAsWithoutIt) {
  const BoxWorld world = adit::testing::makeRoadway(11, 8.0, 24);
  const Eigen::Isometry3d match = poseXYYaw(0, 0, 1.8, 0);
  const Eigen::Isometry3d query = poseXYYaw(0.6, 1.8, 1.8, 25 * kDeg);
  const LoopJob job = jobWithBadSeeds(match, query, sweepAt(world, query, 7), neighbourhoodAt(world, match, 5),
                                      poseXYYaw(-3.0, 2.6, 0, -40 * kDeg));
  LoopBook plain_book;
  const LoopJobOutcome plain = runLoopJob(job, plain_book, jobConfig(true));
  ASSERT_EQ(plain.loops.size(), 1u);
  PlaneTargetCache cache(4);
  for (int run = 0; run < 2; ++run) {
    LoopBook book;
    const LoopJobOutcome cached = runLoopJob(job, book, jobConfig(true), &cache);
    EXPECT_EQ(cached.counts.submaps_reused, run);
    ASSERT_EQ(cached.loops.size(), 1u);
    EXPECT_TRUE(cached.loops[0].T_match_query.isApprox(plain.loops[0].T_match_query, 0.0));
    EXPECT_EQ(cached.loops[0].fitness, plain.loops[0].fitness);
  }
  EXPECT_EQ(cache.builds(), 1u);
}

TEST(KeypointSeed, FindsTheLoopWhereScanContextAndGraphSeedsDoNotFit) {
  const BoxWorld world = adit::testing::makeRoadway(11, 8.0, 24);
  const Eigen::Isometry3d match = poseXYYaw(0, 0, 1.8, 0);
  const Eigen::Isometry3d query = poseXYYaw(0.6, 1.8, 1.8, 25 * kDeg);
  const Sweep q = sweepAt(world, query, 7);
  // The graph has drifted 4 m and 40 degrees between the visits.
  const Eigen::Isometry3d drift = poseXYYaw(-3.0, 2.6, 0, -40 * kDeg);
  const LoopJob job = jobWithBadSeeds(match, query, q, neighbourhoodAt(world, match, 5), drift);

  LoopBook without_book;
  const LoopJobOutcome without = runLoopJob(job, without_book, jobConfig(false));
  EXPECT_TRUE(without.loops.empty());
  EXPECT_EQ(without.counts.rejected_fitness, 1);

  LoopBook book;
  const LoopJobOutcome with = runLoopJob(job, book, jobConfig(true));
  EXPECT_EQ(with.counts.keypoint_seeds, 1);
  EXPECT_EQ(with.counts.keypoint_loops, 1);
  ASSERT_EQ(with.loops.size(), 1u);
  const Eigen::Isometry3d error = (match.inverse() * query).inverse() * with.loops[0].T_match_query;
  std::printf("loop from the keypoints' seed: error %.3f m, %.2f deg, rms %.3f m\n", error.translation().norm(),
              angleDeg(error), with.loops[0].fitness);
  EXPECT_LT(error.translation().norm(), 0.1);
  EXPECT_LT(angleDeg(error), 1.0);
}

TEST(KeypointSeed, RefusesAPlaceWhereKeypointsAndScanContextFindTwoFitsTheOdometryCannotTellApart) {
  // A roadway whose equipment repeats every 20 m. The graph and the Scan Context seed find the true revisit;
  // the query's keypoints are moved one period along the roadway (what an aliased keypoint match gives), so
  // their seed puts the query 20 m further on, where it fits just as tightly. With the odometry uncertain by
  // 10 m between the visits both places pass its gate: no way to tell which is right, so no loop.
  const BoxWorld world = adit::testing::makePeriodicRoadway(9, 20.0, 10, 4.0, -4, 5);  // x from -80 to 120 m
  const Eigen::Isometry3d match = poseXYYaw(0, 0, 1.8, 0);
  const Eigen::Isometry3d query = poseXYYaw(0.3, 0.5, 1.8, 3 * kDeg);
  const Sweep own = sweepAt(world, query, 7);
  std::vector<Eigen::Vector3f> moved = own.keypoints.points();
  const Eigen::Vector3f period = (query.linear().transpose() * Eigen::Vector3d(20, 0, 0)).cast<float>();
  for (Eigen::Vector3f& p : moved) p -= period;
  Sweep q = own;
  q.keypoints = KeyframeKeypoints::encode(moved, own.keypoints.descriptors());
  LoopJob job = jobWithBadSeeds(match, query, q, neighbourhoodAt(world, match, 24), Eigen::Isometry3d::Identity());
  job.candidates[0].candidate.yaw = -3 * kDeg;

  LoopBook without_book;
  const LoopJobOutcome without = runLoopJob(job, without_book, jobConfig(false));
  ASSERT_EQ(without.loops.size(), 1u);  // alone, the true revisit is accepted

  LoopBook book;
  const LoopJobOutcome with = runLoopJob(job, book, jobConfig(true));
  std::printf("keypoint seeds %d, ambiguous %d, loops %zu\n", with.counts.keypoint_seeds, with.counts.rejected_ambiguous,
              with.loops.size());
  EXPECT_EQ(with.counts.keypoint_seeds, 1);
  EXPECT_EQ(with.counts.rejected_ambiguous, 1);
  EXPECT_TRUE(with.loops.empty());

  // Where the odometry is sure enough to rule the other place out (0.5 m between the visits, not 10 m), the
  // fit it allows is the loop.
  LoopJob sure = job;
  sure.chain = sureChain(match, query);
  LoopBook sure_book;
  const LoopJobOutcome resolved = runLoopJob(sure, sure_book, jobConfig(true));
  EXPECT_EQ(resolved.counts.rejected_ambiguous, 0);
  ASSERT_EQ(resolved.loops.size(), 1u);
  EXPECT_LT(((match.inverse() * query).inverse() * resolved.loops[0].T_match_query).translation().norm(), 0.1);

  // The query's own keypoints agree with the fit: accepted as without them.
  job.query_keypoints = std::make_shared<const KeyframeKeypoints>(own.keypoints);
  LoopBook own_book;
  const LoopJobOutcome agreed = runLoopJob(job, own_book, jobConfig(true));
  EXPECT_EQ(agreed.counts.keypoint_seeds, 1);
  EXPECT_EQ(agreed.counts.rejected_ambiguous, 0);
  EXPECT_EQ(agreed.loops.size(), 1u);
}

TEST(LoopJob, RefusesAPlaceWhereScanContextAndGraphSeedsFindTwoFitsTheOdometryCannotTellApart) {
  // The same periodic roadway; the query is one period (20 m) past the candidate keyframe, where the graph
  // rightly puts it. Scan Context matched the two because the place looks the same: its seed (the same place)
  // fits tightly 20 m short of the truth, and used to be the loop. ICP from the graph's seed fits at the truth;
  // with the odometry uncertain by 10 m both pass its gate: no loop.
  const BoxWorld world = adit::testing::makePeriodicRoadway(9, 20.0, 10, 4.0, -4, 5);
  const Eigen::Isometry3d match = poseXYYaw(0, 0, 1.8, 0);
  const Eigen::Isometry3d query = poseXYYaw(20.3, 0.5, 1.8, 3 * kDeg);
  const Sweep q = sweepAt(world, query, 7);
  LoopJob job = jobWithBadSeeds(match, query, q, neighbourhoodAt(world, match, 24), Eigen::Isometry3d::Identity());
  job.candidates[0].candidate.yaw = -3 * kDeg;
  LoopBook book;
  const LoopJobOutcome out = runLoopJob(job, book, jobConfig(false));
  std::printf("ambiguous %d, loops %zu\n", out.counts.rejected_ambiguous, out.loops.size());
  EXPECT_EQ(out.counts.rejected_ambiguous, 1);
  EXPECT_TRUE(out.loops.empty());

  // Where the odometry is sure (0.5 m between the visits), it rules the Scan Context seed's fit out, and the
  // graph's fit, which only checked it, is not taken in its place: no loop, as before the check.
  job.chain = sureChain(match, query);
  LoopBook sure_book;
  const LoopJobOutcome sure = runLoopJob(job, sure_book, jobConfig(false));
  EXPECT_EQ(sure.counts.rejected_ambiguous, 0);
  EXPECT_EQ(sure.counts.rejected_odometry, 1);
  EXPECT_TRUE(sure.loops.empty());
}

TEST(KeypointSeed, KeyframeKeypointsSurviveACheckpointAndOlderRecordsStillLoad) {
  const BoxWorld world = adit::testing::makeRoadway(11, 8.0, 24);
  LoopCloser closer;
  for (int k = 0; k < 4; ++k) {
    PoseEstimate pe;
    pe.utime = k * 1'000'000;
    pe.pose = poseXYYaw(1.5 * k, 0, 1.8, 0);
    LidarScan scan = simulateSweep(world, pe.pose, static_cast<std::uint32_t>(k + 1), 450);
    scan.utime = pe.utime;
    const FeatureSet f = FeatureExtractor(FeatureConfig{}).process(scan, {}, MotionPrior{});
    const auto keypoints = std::make_shared<const KeyframeKeypoints>(KeyframeKeypoints::encode(f.keypoints, f.descriptors));
    closer.process(pe, scan, k == 2 ? nullptr : keypoints);  // keyframe 2: its FEATURES never came
  }
  closer.finish();
  ASSERT_EQ(closer.keyframes().size(), 4u);
  EXPECT_FALSE(closer.keyframeKeypoints(0).empty());
  EXPECT_TRUE(closer.keyframeKeypoints(2).empty());

  std::vector<std::string> records;
  for (int k = 0; k < 4; ++k) records.push_back(closer.keyframeRecord(k));
  LoopCloser restored;
  ASSERT_TRUE(restored.restoreState(closer.saveState(), records));
  for (int k = 0; k < 4; ++k) {
    EXPECT_EQ(restored.keyframeKeypoints(k).points(), closer.keyframeKeypoints(k).points()) << k;
    EXPECT_EQ(restored.keyframeKeypoints(k).descriptors(), closer.keyframeKeypoints(k).descriptors()) << k;
  }
  // Paged with their clouds (a live process), they read back the same, and so do the records.
  restored.pageKeyframesTo(::testing::TempDir() + "keypoint_seed_test.clouds", 1);
  EXPECT_EQ(restored.clouds().pagedClouds(), 3u);
  for (int k = 0; k < 4; ++k) {
    EXPECT_EQ(restored.keyframeKeypoints(k).points(), closer.keyframeKeypoints(k).points()) << k;
    EXPECT_EQ(restored.keyframeKeypoints(k).descriptors(), closer.keyframeKeypoints(k).descriptors()) << k;
    EXPECT_EQ(restored.keyframeRecord(k), records[static_cast<std::size_t>(k)]) << k;
  }

  // A record written before keyframes kept keypoints ends after the step covariance: it loads, without them.
  std::vector<std::string> older = records;
  for (int k = 0; k < 4; ++k) {
    ByteWriter w;
    closer.keyframeKeypoints(k).put(w);
    older[static_cast<std::size_t>(k)].resize(older[static_cast<std::size_t>(k)].size() - w.bytes().size());
  }
  LoopCloser from_older;
  ASSERT_TRUE(from_older.restoreState(closer.saveState(), older));
  for (int k = 0; k < 4; ++k) EXPECT_TRUE(from_older.keyframeKeypoints(k).empty());
  // A record cut inside its keypoints is refused (the closer stays as it was).
  std::vector<std::string> cut = records;
  cut[0].resize(cut[0].size() - 5);
  LoopCloser refused;
  EXPECT_FALSE(refused.restoreState(closer.saveState(), cut));
  EXPECT_TRUE(refused.keyframes().empty());
}
