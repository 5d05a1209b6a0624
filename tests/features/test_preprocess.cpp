// Preprocessing: invalid / range / body-box / outlier removal with counts, ring and time completion,
// degenerate sweeps.
#include "features/feature_extractor.hpp"
#include "features/preprocess.hpp"
#include "synthetic_scans.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>

namespace adit {
namespace {

using features::preprocessScan;
using features::PreprocessReport;
using features::RingCloud;

LidarScan roomScan() { return test::scanScene(test::boxRoom(), Eigen::Isometry3d::Identity()); }

TEST(Preprocess, RemovesInvalidOutOfRangeAndBodyPointsAndCountsThem) {
  LidarScan scan = roomScan();
  const int n = static_cast<int>(scan.points.size());
  LidarPoint bad;
  bad.p = Eigen::Vector3f(std::numeric_limits<float>::quiet_NaN(), 1.0f, 0.0f);
  scan.points.push_back(bad);
  bad.p = Eigen::Vector3f(std::numeric_limits<float>::infinity(), 1.0f, 0.0f);
  scan.points.push_back(bad);
  LidarPoint near;
  near.p = Eigen::Vector3f(0.1f, 0.1f, 0.0f);  // under min_range
  near.dt = -0.05f;
  scan.points.push_back(near);
  LidarPoint body;
  body.p = Eigen::Vector3f(-0.8f, 0.0f, -0.3f);  // inside the body box below
  body.dt = -0.05f;
  scan.points.push_back(body);

  PreprocessConfig cfg;
  cfg.body_box_min = {-1.0f, -0.5f, -0.5f};
  cfg.body_box_max = {-0.6f, 0.5f, 0.0f};
  PreprocessReport rep;
  const RingCloud cloud = preprocessScan(scan, cfg, &rep);
  EXPECT_EQ(rep.points_in, n + 4);
  EXPECT_EQ(rep.removed_invalid, 2);
  EXPECT_EQ(rep.removed_range, 2);
  EXPECT_EQ(rep.removed_outlier, 0);  // a clean room scan has no isolated point
  EXPECT_EQ(static_cast<int>(cloud.points.size()), n);
  ASSERT_EQ(cloud.numRings(), 16);
  for (int r = 0; r < 16; ++r) {
    EXPECT_GT(cloud.ringSize(r), 1000) << r;
    for (int i = cloud.ring_begin[r]; i < cloud.ring_begin[r + 1]; ++i) {
      EXPECT_EQ(cloud.points[i].ring, r);
      if (i > cloud.ring_begin[r]) {
        EXPECT_LE(cloud.points[i - 1].dt, cloud.points[i].dt);
      }
    }
  }
}

TEST(Preprocess, RadiusFilterDropsIsolatedDustButKeepsAThinCable) {
  LidarScan scan = roomScan();
  // Dust: isolated returns 1-2 m from the sensor, on several rings and azimuths.
  for (int k = 0; k < 10; ++k) {
    LidarPoint d;
    const double az = 0.3 + 0.55 * k, range = 1.0 + 0.1 * k;
    d.p = Eigen::Vector3f(static_cast<float>(range * std::cos(az)), static_cast<float>(range * std::sin(az)), 0.05f * k);
    d.ring = static_cast<std::uint16_t>(k % 16);
    d.dt = static_cast<float>(-0.1 * (1.0 - std::fmod(M_PI - az + 2 * M_PI, 2 * M_PI) / (2 * M_PI)));
    scan.points.push_back(d);
  }
  // A thin vertical cable (2 cm) 2.5 m ahead: three returns per ring (0.2 deg = 8.7 mm apart) on rings
  // 5..10 only, in front of the far wall, so its only neighbours are its own returns.
  const std::size_t room_points = scan.points.size() - 10;
  for (int r = 5; r <= 10; ++r) {
    for (int k = -1; k <= 1; ++k) {
      LidarPoint c;
      const double el = (-15.0 + 2.0 * r) * M_PI / 180.0, az = -k * 0.2 * M_PI / 180.0;
      c.p = Eigen::Vector3f(static_cast<float>(2.5 * std::cos(az)), static_cast<float>(2.5 * std::sin(az)),
                            static_cast<float>(2.5 * std::tan(el)));
      c.ring = static_cast<std::uint16_t>(r);
      c.dt = static_cast<float>(-0.05 + k * 0.1 / 1800.0);  // facing forward: half a sweep after the seam
      scan.points.push_back(c);
    }
  }
  PreprocessReport rep;
  const RingCloud cloud = preprocessScan(scan, PreprocessConfig{}, &rep);
  EXPECT_EQ(rep.removed_outlier, 10);
  EXPECT_EQ(cloud.points.size(), room_points + 18);
}

TEST(Preprocess, DerivesRingsFromElevationAndTimeFromAzimuth) {
  const LidarScan truth = roomScan();
  LidarScan scan = truth;
  scan.has_ring = false;
  scan.has_time = false;
  scan.num_beams = 0;
  for (LidarPoint& p : scan.points) {
    p.ring = 0;
    p.dt = 0.0f;
  }
  PreprocessReport rep;
  const RingCloud cloud = preprocessScan(scan, PreprocessConfig{}, &rep);
  EXPECT_TRUE(rep.ring_derived);
  EXPECT_TRUE(rep.time_derived);
  ASSERT_EQ(cloud.points.size(), truth.points.size());
  // Every ring gets the same number of points as in the truth, and times match the true firing times
  // to within one column (0.2 deg of a 0.1 s sweep = 56 us).
  RingCloud reference = preprocessScan(truth, PreprocessConfig{}, nullptr);
  for (int r = 0; r < 16; ++r) EXPECT_EQ(cloud.ringSize(r), reference.ringSize(r)) << r;
  double worst = 0.0;
  for (std::size_t i = 0; i < cloud.points.size(); ++i)
    worst = std::max(worst, std::fabs(static_cast<double>(cloud.points[i].dt - reference.points[i].dt)));
  EXPECT_LT(worst, 60e-6);
}

TEST(Preprocess, VoxelDownsampleKeepsOnePointPerVoxelAtTheCentroid) {
  std::vector<LidarPoint> pts(4);
  pts[0].p = {0.01f, 0.01f, 0.01f};
  pts[1].p = {0.09f, 0.09f, 0.09f};
  pts[2].p = {0.31f, 0.01f, 0.01f};
  pts[3].p = {-0.05f, 0.01f, 0.01f};
  const std::vector<LidarPoint> out = features::voxelDownsample(pts, 0.2f);
  ASSERT_EQ(out.size(), 3u);
  EXPECT_NEAR(out[0].p.x(), 0.05f, 1e-6f);
  EXPECT_NEAR(out[1].p.x(), 0.31f, 1e-6f);
  EXPECT_NEAR(out[2].p.x(), -0.05f, 1e-6f);
}

TEST(Preprocess, DegenerateSweepsGiveFlaggedValidOutput) {
  const FeatureExtractor fx{FeatureConfig{}};
  LidarScan empty;
  empty.num_beams = 16;
  FeatureSet f = fx.process(empty, {}, MotionPrior{});
  EXPECT_TRUE(f.flags & FeatureSet::kEmptySweep);
  EXPECT_TRUE(f.flags & FeatureSet::kFewKeypoints);
  EXPECT_TRUE(f.keypoints.empty());

  LidarScan all_nan = roomScan();
  for (LidarPoint& p : all_nan.points) p.p.x() = std::numeric_limits<float>::quiet_NaN();
  f = fx.process(all_nan, {}, MotionPrior{});
  EXPECT_TRUE(f.flags & FeatureSet::kEmptySweep);
  EXPECT_EQ(f.removed_invalid, f.points_in);

  LidarScan missing_ring = roomScan();
  std::vector<LidarPoint> kept;
  for (const LidarPoint& p : missing_ring.points)
    if (p.ring != 7) kept.push_back(p);
  missing_ring.points = kept;
  f = fx.process(missing_ring, {}, MotionPrior{});
  EXPECT_TRUE(f.flags & FeatureSet::kEmptyRing);
  EXPECT_FALSE(f.flags & FeatureSet::kEmptySweep);
  EXPECT_FALSE(f.surf_flat.empty());

  LidarScan corrupt = roomScan();  // unknown beam count and one absurd ring index
  corrupt.num_beams = 0;
  corrupt.points[100].ring = 65535;
  f = fx.process(corrupt, {}, MotionPrior{});
  EXPECT_EQ(f.removed_range, 1);
  EXPECT_EQ(f.cloud.num_beams, features::kMaxRings);
  EXPECT_TRUE(f.flags & FeatureSet::kEmptyRing);  // rings 16..255 are empty
  EXPECT_FALSE(f.surf_flat.empty());

  LidarScan few;  // three points on one ring: no window, no feature, no crash
  few.num_beams = 16;
  few.has_ring = few.has_time = true;
  for (int k = 0; k < 3; ++k) {
    LidarPoint p;
    p.p = {5.0f, 0.1f * k, 0.0f};
    p.dt = -0.01f * (3 - k);
    few.points.push_back(p);
  }
  f = fx.process(few, {}, MotionPrior{});
  EXPECT_TRUE(f.flags & FeatureSet::kEmptyRing);
  EXPECT_EQ(f.cloud.points.size(), 3u);
  EXPECT_TRUE(f.corner_sharp.empty());
  EXPECT_EQ(f.keypoints.size(), f.descriptors.size());
}

}  // namespace
}  // namespace adit
