// LOAM smoothness and feature selection on synthetic clouds with known edges and planes.
#include "features/feature_extractor.hpp"
#include "features/loam_features.hpp"
#include "features/preprocess.hpp"
#include "features/smoothness.hpp"
#include "synthetic_scans.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <random>
#include <set>

namespace adit {
namespace {

// Distance from p (on a face of box b) to the nearest of the box's 12 edges: the two smallest per-axis
// distances to the box's planes span it.
double distanceToBoxEdge(const test::Box& b, const Eigen::Vector3d& p) {
  std::array<double, 3> d;
  for (int k = 0; k < 3; ++k) d[k] = std::min(std::fabs(p[k] - b.min[k]), std::fabs(p[k] - b.max[k]));
  std::sort(d.begin(), d.end());
  return std::hypot(d[0], d[1]);
}

FeatureSet extract(const LidarScan& scan) { return FeatureExtractor(FeatureConfig{}).process(scan, {}, MotionPrior{}); }

TEST(Smoothness, IsRangeNormalised) {
  // The same room at 3x the size: every point 3x farther, smoothness unchanged (A-LOAM's raw sum would grow 9x).
  test::Scene big = test::boxRoom();
  big.boxes[0].min *= 3.0;
  big.boxes[0].max *= 3.0;
  const LoamConfig cfg;
  const auto small_cloud = features::preprocessScan(test::scanScene(test::boxRoom(), Eigen::Isometry3d::Identity()),
                                                    PreprocessConfig{}, nullptr);
  const auto big_cloud = features::preprocessScan(test::scanScene(big, Eigen::Isometry3d::Identity()),
                                                  PreprocessConfig{}, nullptr);
  ASSERT_EQ(small_cloud.points.size(), big_cloud.points.size());
  const features::PointScores a = features::scorePoints(small_cloud, cfg), b = features::scorePoints(big_cloud, cfg);
  int compared = 0;
  for (std::size_t i = 0; i < a.smoothness.size(); ++i) {
    if (a.smoothness[i] < 0.0f) continue;
    EXPECT_NEAR(a.smoothness[i], b.smoothness[i], 1e-3f) << i;
    ++compared;
  }
  EXPECT_GT(compared, 25000);
}

TEST(LoamFeatures, BoxRoomEdgesAtCornersAndPlanesOnWalls) {
  const test::Scene scene = test::boxRoom();
  const test::Box& room = scene.boxes[0];
  const FeatureSet f = extract(test::scanScene(scene, Eigen::Isometry3d::Identity()));
  ASSERT_FALSE(f.corner_sharp.empty());
  ASSERT_FALSE(f.surf_flat.empty());
  EXPECT_LE(f.corner_sharp.size(), f.corner_less_sharp.size());

  // Precision: every edge feature lies on a true edge of the room (within 2 beam spacings at 9 m = 6 cm).
  double worst_edge = 0.0;
  for (const LidarPoint& p : f.corner_less_sharp) worst_edge = std::max(worst_edge, distanceToBoxEdge(room, p.p.cast<double>()));
  EXPECT_LT(worst_edge, 0.06);
  // Recall: each of the 4 vertical corners is found on at least 10 rings (13-15 rings see each corner).
  const double corners[4][2] = {{-5, -3}, {-5, 5}, {7, -3}, {7, 5}};
  for (const auto& c : corners) {
    std::set<int> rings;
    for (const LidarPoint& p : f.corner_less_sharp)
      if (std::hypot(p.p.x() - c[0], p.p.y() - c[1]) < 0.06) rings.insert(p.ring);
    EXPECT_GE(rings.size(), 10u) << "corner " << c[0] << ", " << c[1];
  }
  // Flat points lie on a wall (exactly: the cloud is noise-free) and away from every edge.
  for (const LidarPoint& p : f.surf_flat) {
    EXPECT_LT(scene.distance(p.p.cast<double>()), 1e-3);
    EXPECT_GT(distanceToBoxEdge(room, p.p.cast<double>()), 0.05);
  }
  // Less-flat: voxel centroids (0.2 m) of non-edge points. More than a voxel from any edge they lie on the
  // walls; only the few voxels straddling an edge (their centroid is off both walls) land near one.
  int near_edge = 0;
  for (const LidarPoint& p : f.surf_less_flat) {
    const double to_edge = distanceToBoxEdge(room, p.p.cast<double>());
    if (to_edge > 0.2) {
      EXPECT_LT(scene.distance(p.p.cast<double>()), 0.01);
    }
    near_edge += to_edge < 0.02;
  }
  EXPECT_LT(near_edge, static_cast<int>(f.surf_less_flat.size()) / 100) << near_edge;
  EXPECT_GT(f.surf_less_flat.size(), 1000u);
  EXPECT_LT(f.surf_less_flat.size(), f.cloud.points.size() / 2);
}

TEST(LoamFeatures, NoisyBoxRoomStillPicksTrueEdges) {
  // 1 cm range noise (VLP-16 class). Measured: sharp picks median 9 mm, worst 39 mm from a true edge; with
  // edge_min_offset at A-LOAM's 0.03 m, 81 of 143 sharp picks were noise more than 0.15 m from any edge.
  const test::Scene scene = test::boxRoom();
  LidarScan scan = test::scanScene(scene, Eigen::Isometry3d::Identity());
  std::mt19937 rng(5);
  std::normal_distribution<float> noise(0.0f, 0.01f);
  for (LidarPoint& p : scan.points) p.p *= 1.0f + noise(rng) / p.p.norm();
  const FeatureSet f = extract(scan);
  ASSERT_GE(f.corner_sharp.size(), 30u);
  for (const LidarPoint& p : f.corner_sharp) EXPECT_LT(distanceToBoxEdge(scene.boxes[0], p.p.cast<double>()), 0.06);
  for (const LidarPoint& p : f.surf_flat) EXPECT_LT(scene.distance(p.p.cast<double>()), 0.05);
}

TEST(LoamFeatures, NoiseFloorFollowsTheMeasuredRangeNoise) {
  // 2 cm range noise (the simulated VLP-16) in the 4 m corridor: the sweep's noise estimate must read it, and
  // sharp picks must stay on the creases. With only the fixed 0.05 m floor (2.5 sigma here) noise spikes on
  // the walls beside the sensor become edges; they slide with the sensor and hold scan matching at zero
  // motion along a featureless roadway. Measured: noise estimate 0.0197 m; sharp picks off the creases
  // 0 of 62 with the noise floor, 110 of 172 without.
  const test::Scene scene = test::corridor();
  LidarScan scan = test::scanScene(scene, Eigen::Isometry3d::Identity());
  std::mt19937 rng(7);
  std::normal_distribution<float> noise(0.0f, 0.02f);
  for (LidarPoint& p : scan.points) p.p *= 1.0f + noise(rng) / p.p.norm();
  const auto offCrease = [](const FeatureSet& f) {
    int off = 0;
    for (const LidarPoint& p : f.corner_sharp)
      off += std::hypot(2.0 - std::fabs(p.p.y()), 1.5 - std::fabs(p.p.z())) > 0.15;
    return off;
  };
  FeatureConfig with_floor, fixed_floor;
  fixed_floor.loam.edge_noise_factor = 0.0f;
  const FeatureSet a = FeatureExtractor(with_floor).process(scan, {}, MotionPrior{});
  const FeatureSet b = FeatureExtractor(fixed_floor).process(scan, {}, MotionPrior{});
  const features::RingCloud rings = features::preprocessScan(scan, with_floor.preprocess, nullptr);
  const float sigma = features::scorePoints(rings, with_floor.loam).noise;
  std::printf("noise estimate %.4f m; sharp off the creases: %d of %zu (noise floor), %d of %zu (fixed floor)\n",
              sigma, offCrease(a), a.corner_sharp.size(), offCrease(b), b.corner_sharp.size());
  EXPECT_NEAR(sigma, 0.02, 0.003);
  EXPECT_LE(offCrease(a), 1);
  EXPECT_GT(offCrease(b), 50);  // what the floor removes
}

TEST(LoamFeatures, CorridorHasEdgesOnlyAlongTheWallFloorCreases) {
  const test::Scene scene = test::corridor();
  const FeatureSet f = extract(test::scanScene(scene, Eigen::Isometry3d::Identity()));
  // Creases: y = +-2 with z = -1.5 or z = +1.5.
  for (const LidarPoint& p : f.corner_less_sharp) {
    const double dy = 2.0 - std::fabs(p.p.y()), dz = 1.5 - std::fabs(p.p.z());
    EXPECT_LT(std::hypot(dy, dz), 0.06) << p.p.transpose();
  }
  // Planes on all four surfaces.
  int on_wall = 0, on_floor = 0, on_ceiling = 0;
  for (const LidarPoint& p : f.surf_flat) {
    EXPECT_LT(scene.distance(p.p.cast<double>()), 1e-3);
    on_wall += std::fabs(std::fabs(p.p.y()) - 2.0f) < 1e-3f;
    on_floor += std::fabs(p.p.z() + 1.5f) < 1e-3f;
    on_ceiling += std::fabs(p.p.z() - 1.5f) < 1e-3f;
  }
  EXPECT_GT(on_wall, 20);
  EXPECT_GT(on_floor, 20);
  EXPECT_GT(on_ceiling, 20);
}

TEST(LoamFeatures, OccludedSideOfADepthJumpIsNotAFeature) {
  // A pillar in a room: the wall points right behind the pillar's silhouette are occluded edges and must
  // not be picked; the pillar's own silhouette points may.
  test::Scene scene = test::boxRoom();
  scene.boxes.push_back({{2.0, -0.3, -1.5}, {2.6, 0.3, 2.5}, false});
  const FeatureSet f = extract(test::scanScene(scene, Eigen::Isometry3d::Identity()));
  int silhouette = 0;  // edge points on the pillar's own silhouette (legitimate): 32 (2 sides x 16 rings)
  for (const LidarPoint& p : f.corner_less_sharp) {
    const double az = std::atan2(p.p.y(), p.p.x());
    const bool near_silhouette = std::fabs(std::fabs(az) - std::atan2(0.3, 2.0)) < 0.03;  // pillar's sides
    silhouette += near_silhouette && p.p.x() < 2.7f;
    // Without the occlusion test (occlusion_ratio = 100) 32 wall points behind the silhouette are picked.
    if (near_silhouette) {
      EXPECT_LT(p.p.x(), 2.7f) << "occluded wall point picked: " << p.p.transpose();
    }
  }
  EXPECT_GE(silhouette, 16);
  for (const LidarPoint& p : f.surf_flat) {
    const double az = std::atan2(p.p.y(), p.p.x());
    if (std::fabs(std::fabs(az) - std::atan2(0.3, 2.0)) < 0.03) {
      EXPECT_LT(p.p.x(), 2.7f);
    }
  }
}

TEST(LoamFeatures, SectorCapsAndSuppressionLimitCounts) {
  const FeatureSet f = extract(test::scanScene(test::boxRoom(), Eigen::Isometry3d::Identity()));
  const LoamConfig cfg;
  EXPECT_LE(f.corner_sharp.size(), static_cast<std::size_t>(16 * cfg.sectors * cfg.max_sharp));
  EXPECT_LE(f.surf_flat.size(), static_cast<std::size_t>(16 * cfg.sectors * cfg.max_flat));
  // Suppression: two sharp points of one ring are never adjacent on the same surface (> 1 beam spacing).
  for (std::size_t i = 0; i < f.corner_sharp.size(); ++i)
    for (std::size_t j = i + 1; j < f.corner_sharp.size(); ++j)
      if (f.corner_sharp[i].ring == f.corner_sharp[j].ring) {
        EXPECT_GT((f.corner_sharp[i].p - f.corner_sharp[j].p).norm(), 0.02f);
      }
}

// features.threads only spreads the work: every set, keypoint, descriptor, flag and the thinned sweep are the
// same bytes for one thread or several (the rings' noise figure is a median, independent of how the rings
// are grouped), on a moving noisy sweep of the pillar hall with dust, deskewed and not.
TEST(FeatureExtractor, TheSameFeaturesForAnyThreadCount) {
  LidarScan scan = test::scanScene(test::pillarHall(), [](double t) {
    Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
    T.translation() = Eigen::Vector3d(1.5 * t, 0.2 * t, 0.0);
    return T;
  });
  std::mt19937 rng(7);
  std::normal_distribution<float> noise(0.0f, 0.01f);
  for (LidarPoint& p : scan.points) p.p *= 1.0f + noise(rng) / p.p.norm();
  // Dust: lone returns near the sensor that the radius outlier filter removes (its counts are compared too).
  std::uniform_real_distribution<float> near(-3.0f, 3.0f);
  for (int i = 0; i < 40; ++i) {
    LidarPoint dust = scan.points[static_cast<std::size_t>(i) * scan.points.size() / 40];
    dust.p = Eigen::Vector3f(near(rng), near(rng), 0.3f * near(rng));
    if (dust.p.norm() > 1.0f) scan.points.push_back(dust);
  }
  MotionPrior prior;
  prior.T_prev_curr.translation() = Eigen::Vector3d(0.15, 0.02, 0.0);
  prior.dt_s = 0.1;
  prior.valid = true;
  const auto bytes = [](const std::vector<LidarPoint>& v) {
    std::vector<float> out;
    for (const LidarPoint& p : v) out.insert(out.end(), {p.p.x(), p.p.y(), p.p.z(), p.intensity, p.dt, float(p.ring)});
    return out;
  };
  for (const float voxel : {0.0f, 0.1f}) {
    FeatureConfig one;
    one.threads = 1;
    const FeatureSet a = FeatureExtractor(one).process(scan, {}, prior, voxel);
    ASSERT_GT(a.corner_sharp.size(), 0u);
    ASSERT_GT(a.keypoints.size(), 0u);
    ASSERT_GT(a.removed_outlier, 0);
    for (const int threads : {2, 3, 16}) {
      FeatureConfig many;
      many.threads = threads;
      const FeatureExtractor extractor(many);
      for (int repeat = 0; repeat < 3; ++repeat) {
        const FeatureSet b = extractor.process(scan, {}, prior, voxel);
        EXPECT_EQ(bytes(a.corner_sharp), bytes(b.corner_sharp)) << threads;
        EXPECT_EQ(bytes(a.corner_less_sharp), bytes(b.corner_less_sharp)) << threads;
        EXPECT_EQ(bytes(a.surf_flat), bytes(b.surf_flat)) << threads;
        EXPECT_EQ(bytes(a.surf_less_flat), bytes(b.surf_less_flat)) << threads;
        EXPECT_EQ(bytes(a.cloud.points), bytes(b.cloud.points)) << threads;
        ASSERT_EQ(a.keypoints.size(), b.keypoints.size());
        for (std::size_t i = 0; i < a.keypoints.size(); ++i) EXPECT_EQ(a.keypoints[i], b.keypoints[i]);
        EXPECT_EQ(a.descriptors, b.descriptors);
        EXPECT_EQ(a.flags, b.flags);
        EXPECT_EQ(a.removed_outlier, b.removed_outlier);
      }
    }
    // The thinned sweep is features::voxelDownsample of the whole one.
    if (voxel > 0.0f) {
      const FeatureSet whole = FeatureExtractor(one).process(scan, {}, prior, 0.0f);
      EXPECT_EQ(bytes(a.cloud.points), bytes(features::voxelDownsample(whole.cloud.points, voxel)));
      EXPECT_LT(a.cloud.points.size(), whole.cloud.points.size());
    }
  }
}

}  // namespace
}  // namespace adit
