// LinK3D: clustering (no duplicated points on merge), descriptor invariance, one-to-one matching and RANSAC
// recovery of a known yaw + translation.
#include "features/feature_extractor.hpp"
#include "features/link3d.hpp"
#include "features/link3d_match.hpp"
#include "synthetic_scans.hpp"

#include "core/geometry.hpp"

#include <gtest/gtest.h>

#include <cstdio>
#include <cstring>
#include <random>
#include <set>

namespace adit {
namespace {

Eigen::Isometry3d yawAndShift(double yaw_deg, const Eigen::Vector3d& t) {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = Eigen::AngleAxisd(yaw_deg * M_PI / 180.0, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  T.translation() = t;
  return T;
}

LidarScan transformed(const LidarScan& scan, const Eigen::Isometry3d& T) {
  LidarScan out = scan;
  for (LidarPoint& p : out.points) p.p = (T * p.p.cast<double>()).cast<float>();
  return out;
}

double angleDeg(const Eigen::Isometry3d& T) { return rotationAngle(T) * 180.0 / M_PI; }

TEST(LinK3dClusters, MergingAcrossASectorBorderDoesNotDuplicatePoints) {
  // 20 edge points of one vertical edge at 10 m, half just below and half just above the 3 deg border
  // between sectors 0 and 1, on 10 rings. The merged cluster must hold exactly 20 points (the reference
  // code's merge loop would also merge a cluster with itself and count its points twice).
  features::RingCloud cloud;
  cloud.ring_begin = {0};
  for (int r = 0; r < 10; ++r) {
    for (double az_deg : {2.95, 3.05}) {
      LidarPoint p;
      const double az = az_deg * M_PI / 180.0;
      p.p = Eigen::Vector3f(static_cast<float>(10 * std::cos(az)), static_cast<float>(10 * std::sin(az)), 0.2f * r);
      p.ring = static_cast<std::uint16_t>(r);
      cloud.points.push_back(p);
    }
    cloud.ring_begin.push_back(static_cast<int>(cloud.points.size()));
  }
  features::PointScores scores;
  for (const LidarPoint& p : cloud.points) {
    scores.range.push_back(p.p.norm());
    scores.offset.push_back(1.0f);
    scores.smoothness.push_back(0.9f);
    scores.usable.push_back(1);
  }
  LinK3dConfig cfg;
  cfg.min_cluster_points = 1;
  cfg.min_cluster_rings = 1;
  const auto clusters = features::extractLinK3dClusters(cloud, scores, cfg);
  ASSERT_EQ(clusters.size(), 1u);
  EXPECT_EQ(clusters[0].points, 20);
  EXPECT_EQ(clusters[0].rings, 10);
  // With the default threshold of 8 points, 10 distinct points over 10 rings on one side alone also pass,
  // but 5 points do not.
  cfg = LinK3dConfig{};
  cloud.points.resize(10);
  cloud.ring_begin = {0, 2, 4, 6, 8, 10};
  for (auto* v : {&scores.range, &scores.offset, &scores.smoothness}) v->resize(10);
  scores.usable.resize(10);
  EXPECT_EQ(features::extractLinK3dClusters(cloud, scores, cfg).size(), 1u);
  cloud.points.resize(6);  // 6 points over 3 rings: below min_cluster_points
  cloud.ring_begin = {0, 2, 4, 6};
  EXPECT_TRUE(features::extractLinK3dClusters(cloud, scores, cfg).empty());
}

TEST(LinK3dDescriptor, InvariantToYawAndTranslation) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<float> u(-20.0f, 20.0f);
  std::vector<Eigen::Vector3f> kp, moved;
  const Eigen::Isometry3d T = yawAndShift(37.0, {3.0, -2.0, 0.5});
  for (int i = 0; i < 40; ++i) {
    kp.emplace_back(u(rng), u(rng), 0.1f * u(rng));
    moved.push_back((T * kp.back().cast<double>()).cast<float>());
  }
  const auto a = features::computeLinK3dDescriptors(kp), b = features::computeLinK3dDescriptors(moved);
  ASSERT_EQ(a.size(), 40u);
  for (int i = 0; i < 40; ++i) {
    int filled = 0;
    for (float v : a[i]) filled += v != 0.0f;
    EXPECT_GE(filled, 30);  // 39 others over 3 orientations, a few sharing a bin
    EXPECT_EQ(linK3dScore(a[i], b[i], 0.2f), filled) << i;
  }
  const auto matches = matchLinK3d(a, b, LinK3dConfig{});
  ASSERT_EQ(matches.size(), 40u);
  for (const LinK3dMatch& m : matches) EXPECT_EQ(m.a, m.b);
}

TEST(LinK3dMatch, OneToOneAndAboveThreshold) {
  std::mt19937 rng(3);
  std::uniform_real_distribution<float> u(0.5f, 10.0f);
  std::vector<LinK3dDescriptor> a(30), b(25);
  for (auto* set : {&a, &b})
    for (LinK3dDescriptor& d : *set)
      for (float& v : d) v = (rng() % 3 == 0) ? u(rng) : 0.0f;
  b[4] = a[0];  // two of a agree with b[4]; only the better one may keep it
  b[4][0] = a[0][0] = 3.0f;
  a[1] = a[0];
  a[1][5] = a[0][5] + 1.0f;
  const LinK3dConfig cfg;
  const auto matches = matchLinK3d(a, b, cfg);
  std::set<int> as, bs;
  for (const LinK3dMatch& m : matches) {
    EXPECT_TRUE(as.insert(m.a).second);
    EXPECT_TRUE(bs.insert(m.b).second);
    EXPECT_GE(m.score, cfg.min_score);
    EXPECT_EQ(m.score, linK3dScore(a[m.a], b[m.b], cfg.bin_tolerance));
  }
  bool found = false;
  for (const LinK3dMatch& m : matches) found |= (m.b == 4 && m.a == 0);
  EXPECT_TRUE(found);
}

TEST(LinK3d, RecoversAKnownYawAndTranslationOfTheSameCloud) {
  const LidarScan scan = test::scanScene(test::pillarHall(), Eigen::Isometry3d::Identity());
  const Eigen::Isometry3d T = yawAndShift(25.0, {1.2, -0.7, 0.1});  // b = T * a
  const FeatureExtractor fx{FeatureConfig{}};
  const FeatureSet a = fx.process(scan, {}, MotionPrior{});
  const FeatureSet b = fx.process(transformed(scan, T), {}, MotionPrior{});
  ASSERT_GE(a.keypoints.size(), 15u);  // about one per pillar (its corners merge) + room corners
  EXPECT_FALSE(a.flags & FeatureSet::kFewKeypoints);
  const auto matches = matchLinK3d(a, b, fx.config().link3d);
  EXPECT_GE(matches.size(), a.keypoints.size() * 8 / 10);
  const RansacResult r = estimateTransformRansac(a.keypoints, b.keypoints, matches, fx.config().ransac);
  ASSERT_TRUE(r.ok);
  const Eigen::Isometry3d err = T * r.T_a_b;  // T_a_b should be T^-1
  std::printf("same cloud moved: %zu keypoints, %zu matches, %zu inliers, error %.4f m %.4f deg\n", a.keypoints.size(),
              matches.size(), r.inliers.size(), err.translation().norm(), angleDeg(err));
  EXPECT_LT(err.translation().norm(), 0.05);
  EXPECT_LT(angleDeg(err), 0.5);
}

TEST(LinK3d, RecoversTheMotionBetweenTwoSimulatedViewpoints) {
  // A real second sweep (re-cast from a pose 1 m ahead, turned 8 deg), without and with 2 cm range noise:
  // cluster centroids shift with the rings that see each pillar, so tolerances are looser than for the
  // same cloud moved. Measured: 0.017 m / 0.04 deg noise-free, 0.026 m / 0.14 deg at 2 cm.
  const test::Scene hall = test::pillarHall();
  const Eigen::Isometry3d T_a_b_true = yawAndShift(8.0, {1.0, 0.3, 0.0});
  const FeatureExtractor fx{FeatureConfig{}};
  for (float sigma : {0.0f, 0.02f}) {
    std::mt19937 rng(5);
    std::normal_distribution<float> noise(0.0f, 1.0f);
    const auto noisy = [&](LidarScan scan) {
      for (LidarPoint& p : scan.points) p.p *= 1.0f + sigma * noise(rng) / p.p.norm();
      return scan;
    };
    const FeatureSet a = fx.process(noisy(test::scanScene(hall, Eigen::Isometry3d::Identity())), {}, MotionPrior{});
    const FeatureSet b = fx.process(noisy(test::scanScene(hall, T_a_b_true)), {}, MotionPrior{});
    const auto matches = matchLinK3d(a, b, fx.config().link3d);
    const RansacResult r = estimateTransformRansac(a.keypoints, b.keypoints, matches, fx.config().ransac);
    ASSERT_TRUE(r.ok) << sigma;
    const Eigen::Isometry3d err = T_a_b_true.inverse() * r.T_a_b;
    std::printf("two viewpoints, noise %.2f m: %zu / %zu keypoints, %zu matches, %zu inliers, error %.4f m %.4f deg\n",
                sigma, a.keypoints.size(), b.keypoints.size(), matches.size(), r.inliers.size(),
                err.translation().norm(), angleDeg(err));
    EXPECT_LT(err.translation().norm(), 0.10) << sigma;
    EXPECT_LT(angleDeg(err), 0.5) << sigma;
    EXPECT_GE(r.inliers.size(), 10u) << sigma;
  }
}

TEST(LinK3d, DegenerateInputsAreFlaggedNotFatal) {
  const FeatureExtractor fx{FeatureConfig{}};
  const FeatureSet corridor = fx.process(test::scanScene(test::corridor(), Eigen::Isometry3d::Identity()), {}, MotionPrior{});
  EXPECT_TRUE(corridor.flags & FeatureSet::kFewKeypoints);  // smooth roadway: nothing vertical to cluster
  EXPECT_EQ(corridor.keypoints.size(), corridor.descriptors.size());
  const FeatureSet empty = fx.process(LidarScan{}, {}, MotionPrior{});
  EXPECT_TRUE(matchLinK3d(empty, corridor, fx.config().link3d).empty());
  EXPECT_FALSE(estimateTransformRansac({}, {}, {}, fx.config().ransac).ok);
  // Out-of-range indices are rejected, not dereferenced.
  EXPECT_FALSE(estimateTransformRansac({}, {}, {{0, 0, 9}, {1, 1, 9}, {2, 2, 9}}, fx.config().ransac).ok);
}

TEST(LinK3d, OutputIsDeterministic) {
  const LidarScan scan = test::scanScene(test::pillarHall(), Eigen::Isometry3d::Identity());
  const FeatureExtractor fx{FeatureConfig{}};
  const FeatureSet x = fx.process(scan, {}, MotionPrior{}), y = fx.process(scan, {}, MotionPrior{});
  ASSERT_EQ(x.keypoints.size(), y.keypoints.size());
  ASSERT_EQ(x.surf_less_flat.size(), y.surf_less_flat.size());
  EXPECT_EQ(0, std::memcmp(x.keypoints.data(), y.keypoints.data(), x.keypoints.size() * sizeof(Eigen::Vector3f)));
  EXPECT_EQ(0, std::memcmp(x.descriptors.data(), y.descriptors.data(), x.descriptors.size() * sizeof(LinK3dDescriptor)));
  const auto m1 = matchLinK3d(x, y, fx.config().link3d), m2 = matchLinK3d(x, y, fx.config().link3d);
  const RansacResult r1 = estimateTransformRansac(x.keypoints, y.keypoints, m1, fx.config().ransac);
  const RansacResult r2 = estimateTransformRansac(x.keypoints, y.keypoints, m2, fx.config().ransac);
  EXPECT_TRUE(r1.T_a_b.matrix() == r2.T_a_b.matrix());
}

}  // namespace
}  // namespace adit
