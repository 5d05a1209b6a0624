// LinK3D on real 64-beam data: RANSAC on matched keypoints of consecutive kitti_mini scans recovers the
// ground-truth relative pose. Scans come from lib/io's KITTI reader (rings from scan order, per-point time).
#include "core/geometry.hpp"
#include "features/feature_extractor.hpp"
#include "features/link3d_match.hpp"
#include "io/kitti.hpp"

#include <gtest/gtest.h>

#include <cstdio>
#include <string>

namespace adit {
namespace {

const std::string kRoot = std::string(ADIT_SHARED_DATA_DIR) + "/kitti_mini";

struct PairError {
  double translation_m, rotation_deg;
  std::size_t inliers;
  bool ok;
};

// Relative pose of scan i+1 in scan i: estimated from LinK3D vs ground truth (T_velo = Tr^-1 P Tr).
PairError pairError(const io::KittiSequence& seq, const Trajectory& gt, std::size_t i, const FeatureExtractor& fx) {
  const FeatureSet a = fx.process(seq.scan(i), {}, MotionPrior{});
  const FeatureSet b = fx.process(seq.scan(i + 1), {}, MotionPrior{});
  const auto matches = matchLinK3d(a, b, fx.config().link3d);
  const RansacResult r = estimateTransformRansac(a.keypoints, b.keypoints, matches, fx.config().ransac);
  const Eigen::Isometry3d T_true = gt[i].pose.inverse() * gt[i + 1].pose;
  const Eigen::Isometry3d err = T_true.inverse() * r.T_a_b;
  std::printf("  scan %zu->%zu: %zu/%zu keypoints, %zu matches, %zu inliers, error %.3f m %.3f deg (moved %.2f m)\n", i,
              i + 1, a.keypoints.size(), b.keypoints.size(), matches.size(), r.inliers.size(),
              err.translation().norm(), rotationAngle(err) * 180.0 / M_PI, T_true.translation().norm());
  return {err.translation().norm(), rotationAngle(err) * 180.0 / M_PI, r.inliers.size(), r.ok};
}

class KittiLinK3d : public ::testing::TestWithParam<const char*> {};

// 01 (highway) and 02 (rural) have reliable ground truth: 0.3 m / 1 deg on every consecutive pair.
// Measured (default config): 01 worst 0.14 m / 0.25 deg, 02 worst 0.21 m / 0.57 deg.
TEST_P(KittiLinK3d, ConsecutiveScansRecoverGroundTruthRelativePose) {
  const io::KittiSequence seq = io::KittiSequence::open(kRoot, GetParam());
  const Trajectory gt = seq.groundTruthLidar(seq.defaultPosesFile());
  const FeatureExtractor fx{FeatureConfig{}};
  for (std::size_t i = 0; i + 1 < seq.size(); ++i) {
    const PairError e = pairError(seq, gt, i, fx);
    EXPECT_TRUE(e.ok) << "pair " << i;
    EXPECT_LT(e.translation_m, 0.3) << "pair " << i;
    EXPECT_LT(e.rotation_deg, 1.0) << "pair " << i;
  }
}

INSTANTIATE_TEST_SUITE_P(Sequences, KittiLinK3d, ::testing::Values("01", "02"));

// 00: its ground truth advances a constant 0.86 m per scan while the car accelerates from ~0.67 to ~0.82 m
// (see data README), so translation is judged with that ~0.2 m allowance and rotation at 1 deg.
// Measured: worst 0.19 m / 0.24 deg.
TEST(KittiLinK3d, Sequence00JudgedOnRotation) {
  const io::KittiSequence seq = io::KittiSequence::open(kRoot, "00");
  const Trajectory gt = seq.groundTruthLidar(seq.defaultPosesFile());
  const FeatureExtractor fx{FeatureConfig{}};
  for (std::size_t i = 0; i + 1 < seq.size(); ++i) {
    const PairError e = pairError(seq, gt, i, fx);
    EXPECT_TRUE(e.ok) << "pair " << i;
    EXPECT_LT(e.rotation_deg, 1.0) << "pair " << i;
    EXPECT_LT(e.translation_m, 0.3 + 0.2) << "pair " << i;
  }
}

}  // namespace
}  // namespace adit
