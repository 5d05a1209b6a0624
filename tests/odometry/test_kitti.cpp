// Odometry and mapping on real 64-beam data (kitti_mini 00, 01, 02; 10 scans each): relative pose error per
// consecutive pair against ground truth in the lidar frame (T_velo_i = Tr^-1 P_i Tr, from lib/io).
// Full pipeline as adit runs it: FeatureExtractor (deskew with the odometry's motion prior), LinK3D RANSAC
// seed, scan-to-scan odometry, scan-to-map mapping.
#include "core/config.hpp"
#include "core/geometry.hpp"
#include "features/feature_extractor.hpp"
#include "features/link3d_match.hpp"
#include "io/kitti.hpp"
#include "mapping/scan_to_map.hpp"
#include "odometry/scan_to_scan.hpp"

#include <gtest/gtest.h>

#include <cstdio>
#include <string>

namespace adit {
namespace {

const std::string kRoot = std::string(ADIT_SHARED_DATA_DIR) + "/kitti_mini";
constexpr double kDeg = M_PI / 180.0;

struct PairErrors {
  std::vector<double> odom_t, odom_r, map_t, map_r;
  int seeded_by_link3d = 0, failed = 0;
};

// The 64-beam settings adit ships (launch/sensors/hdl64.yaml), its odometry.* and mapping.* keys read from the
// file itself, so the test judges what a KITTI replay runs (the feature stage keeps its defaults here).
const Config& hdl64() {
  static const Config c = Config::fromYamlFile(std::string(ADIT_SOURCE_DIR) + "/launch/sensors/hdl64.yaml");
  return c;
}
MapperConfig kittiMapperConfig() { return mapperConfigFrom(hdl64()); }
ScanToScanConfig kittiOdometryConfig() { return scanToScanConfigFrom(hdl64()); }

PairErrors runSequence(const std::string& name, bool aloam) {
  const io::KittiSequence seq = io::KittiSequence::open(kRoot, name);
  const Trajectory gt = seq.groundTruthLidar(seq.defaultPosesFile());
  const FeatureExtractor fx{FeatureConfig{}};
  ScanToScanOdometry odom(aloam ? aloamOdometryConfig() : kittiOdometryConfig());
  MapperConfig mc = kittiMapperConfig();
  if (aloam) mc.registration.degeneracy_prior = false, mc.compensate_raw_sweeps = false;
  ScanToMapMapper mapper(mc);
  PairErrors errors;
  FeatureSet previous;
  std::vector<PoseEstimate> odo, map;
  for (std::size_t i = 0; i < seq.size(); ++i) {
    const LidarScan scan = seq.scan(i);
    MotionPrior motion;
    if (i > 0) {
      motion.T_prev_curr = odom.predictMotion(scan.utime);
      motion.dt_s = toSeconds(scan.utime - seq.utime(i - 1));
      motion.valid = i > 1 && !aloam;  // scans 0 and 1 arrive raw: no velocity yet (the odometry compensates)
    }
    const FeatureSet f = fx.process(scan, {}, motion);
    std::optional<Eigen::Isometry3d> seed;
    int seed_flags = 0;
    if (i > 0) {  // the ablation's odometry ignores this seed (use_link3d_seed = false)
      const auto matches = matchLinK3d(previous, f, fx.config().link3d);
      const RansacResult r = estimateTransformRansac(previous.keypoints, f.keypoints, matches, fx.config().ransac);
      if (r.ok) seed = r.T_a_b, seed_flags = PoseEstimate::kSeededByLinK3d;
    }
    odo.push_back(odom.process(f, seed, seed_flags));
    map.push_back(mapper.process(f, odo.back()));
    if (odo.back().flags & PoseEstimate::kSeededByLinK3d) ++errors.seeded_by_link3d;
    if ((odo.back().flags | map.back().flags) & PoseEstimate::kRegistrationFailed) ++errors.failed;
    if (i > 0) {
      const Eigen::Isometry3d truth = gt[i - 1].pose.inverse() * gt[i].pose;
      const Eigen::Isometry3d eo = truth.inverse() * (odo[i - 1].pose.inverse() * odo[i].pose);
      const Eigen::Isometry3d em = truth.inverse() * (map[i - 1].pose.inverse() * map[i].pose);
      errors.odom_t.push_back(eo.translation().norm());
      errors.odom_r.push_back(rotationAngle(eo) / kDeg);
      errors.map_t.push_back(em.translation().norm());
      errors.map_r.push_back(rotationAngle(em) / kDeg);
      std::printf("  %s %zu->%zu moved %.2f m: odometry %.3f m %.3f deg, mapping %.3f m %.3f deg, flags %d/%d\n",
                  name.c_str(), i - 1, i, truth.translation().norm(), errors.odom_t.back(), errors.odom_r.back(),
                  errors.map_t.back(), errors.map_r.back(), odo.back().flags, map.back().flags);
    }
    previous = f;
  }
  return errors;
}

double worst(const std::vector<double>& v) { return v.empty() ? 0.0 : *std::max_element(v.begin(), v.end()); }

class KittiOdometry : public ::testing::TestWithParam<const char*> {};

// 01 (highway, few features) and 02 (rural) have reliable ground truth: 0.1 m and 0.3 deg per pair.
// Measured: 01 worst 0.021 m / 0.22 deg (odometry), 0.040 m / 0.18 deg (mapping); 02 worst 0.057 m / 0.16 deg
// and 0.050 m / 0.11 deg (before the edge noise floor: 0.021 / 0.21, 0.036 / 0.17; 0.052 / 0.16, 0.061 / 0.12).
TEST_P(KittiOdometry, RelativePoseErrorPerPairIsSmall) {
  const PairErrors e = runSequence(GetParam(), false);
  std::printf("%s worst: odometry %.3f m %.3f deg, mapping %.3f m %.3f deg; LinK3D-seeded %d/9\n", GetParam(),
              worst(e.odom_t), worst(e.odom_r), worst(e.map_t), worst(e.map_r), e.seeded_by_link3d);
  EXPECT_EQ(e.failed, 0);
  ASSERT_EQ(e.odom_t.size(), 9u);
  for (std::size_t i = 0; i < e.odom_t.size(); ++i) {
    EXPECT_LT(e.odom_t[i], 0.1) << "pair " << i;
    EXPECT_LT(e.odom_r[i], 0.3) << "pair " << i;
    EXPECT_LT(e.map_t[i], 0.1) << "pair " << i;
    EXPECT_LT(e.map_r[i], 0.3) << "pair " << i;
  }
}

INSTANTIATE_TEST_SUITE_P(Sequences, KittiOdometry, ::testing::Values("01", "02"));

// 00: its ground truth for these frames is interpolated, not measured: every pair advances 0.86 m and turns
// 0.139 deg about the same axis to 4 digits, while the car accelerates from ~0.67 to ~0.82 m per scan (data
// README) and real pairs (01, 02) show 0.1-0.2 deg of pitch/roll jitter from pair to pair. Translation is
// judged with the README's ~0.2 m allowance. Rotation: scan-to-scan odometry and the mapper's poses get 0.1 and
// 0.05 deg more than 01 and 02's 0.3 deg for the missing jitter; means at 0.25 deg. Measured: worst 0.18 m /
// 0.32 deg (odometry), 0.18 m / 0.301 deg (mapping, the last pair; 0.296 with 0.8 m map surfaces, 0.308 with
// surfaces registered at 0.6 m: it sits at 0.3 whatever the resolution), mean 0.22 deg.
TEST(KittiOdometry, Sequence00) {
  const PairErrors e = runSequence("00", false);
  std::printf("00 worst: odometry %.3f m %.3f deg, mapping %.3f m %.3f deg; LinK3D-seeded %d/9\n", worst(e.odom_t),
              worst(e.odom_r), worst(e.map_t), worst(e.map_r), e.seeded_by_link3d);
  EXPECT_EQ(e.failed, 0);
  ASSERT_EQ(e.odom_t.size(), 9u);
  double mean_odom_r = 0, mean_map_r = 0;
  for (std::size_t i = 0; i < e.odom_t.size(); ++i) {
    EXPECT_LT(e.odom_r[i], 0.4) << "pair " << i;
    EXPECT_LT(e.map_r[i], 0.35) << "pair " << i;
    EXPECT_LT(e.odom_t[i], 0.2) << "pair " << i;
    EXPECT_LT(e.map_t[i], 0.2) << "pair " << i;
    mean_odom_r += e.odom_r[i] / 9.0;
    mean_map_r += e.map_r[i] / 9.0;
  }
  EXPECT_LT(mean_odom_r, 0.25);
  EXPECT_LT(mean_map_r, 0.25);
}

// The start-up search screens its seeds on ~200 of a 64-beam sweep's ~2,300 sharp and flat points and refines
// the winner on all of them: the first pair, from no seed (0.9-1.5 m between these scans), must end where the
// search on all points ends and where the car went (00 with the 0.2 m of its interpolated ground truth, see
// Sequence00). Measured: the two within 5 mm and 0.001 deg of each other; 01, 02 0.008-0.021 m and 0.02-0.04 deg
// from the truth, 00 0.185 m.
TEST(KittiOdometry, StartUpScreenFindsWhatTheFullSearchFinds) {
  for (const char* name : {"00", "01", "02"}) {
    const io::KittiSequence seq = io::KittiSequence::open(kRoot, name);
    const Trajectory gt = seq.groundTruthLidar(seq.defaultPosesFile());
    const Eigen::Isometry3d truth = gt[0].pose.inverse() * gt[1].pose;
    const FeatureExtractor fx{FeatureConfig{}};
    const FeatureSet f0 = fx.process(seq.scan(0), {}, MotionPrior{}), f1 = fx.process(seq.scan(1), {}, MotionPrior{});
    ASSERT_GT(f1.corner_sharp.size() + f1.surf_flat.size(), 1500u) << name << ": a sweep the screen thins";
    Eigen::Isometry3d step[2];
    for (int screen : {0, 1}) {
      ScanToScanConfig c = kittiOdometryConfig();
      if (!screen) c.startup_screen_points = 0;
      ScanToScanOdometry odom(c);
      const PoseEstimate p0 = odom.process(f0, std::nullopt, 0), p1 = odom.process(f1, std::nullopt, 0);
      EXPECT_FALSE(p1.flags & PoseEstimate::kRegistrationFailed) << name;
      step[screen] = p0.pose.inverse() * p1.pose;
      const Eigen::Isometry3d e = truth.inverse() * step[screen];
      std::printf("  %s first pair (moved %.2f m), screen %s: %.3f m %.3f deg from the truth\n", name,
                  truth.translation().norm(), screen ? "on" : "off", e.translation().norm(), rotationAngle(e) / kDeg);
      EXPECT_LT(e.translation().norm(), std::string(name) == "00" ? 0.2 : 0.1) << name;
      EXPECT_LT(rotationAngle(e), 0.3 * kDeg) << name;
    }
    const Eigen::Isometry3d d = step[0].inverse() * step[1];
    EXPECT_LT(d.translation().norm(), 0.01) << name;
    EXPECT_LT(rotationAngle(d), 0.05 * kDeg) << name;
  }
}

// The A-LOAM ablation (no LinK3D seed, no deskew, A-LOAM lines and planes, no degeneracy prior) is the
// "before" of the comparison: it must run and track, not excel. Without a seed its first pairs start from
// zero motion at 1-1.5 m per scan and need ~4 scans to catch up (measured 02 after mapping: 1.08, 0.65,
// 0.33 m on the first three pairs, where the seeded pipeline errs <= 0.06 m); from pair 4 on it is judged at
// 0.1 m / 0.3 deg (measured worst 0.078 m).
TEST(KittiOdometry, AloamAblationTracksAfterStartUp) {
  for (const char* name : {"01", "02"}) {
    const PairErrors e = runSequence(name, true);
    std::printf("%s A-LOAM ablation worst: odometry %.3f m %.3f deg, mapping %.3f m %.3f deg; seeded %d\n", name,
                worst(e.odom_t), worst(e.odom_r), worst(e.map_t), worst(e.map_r), e.seeded_by_link3d);
    EXPECT_EQ(e.seeded_by_link3d, 0);
    EXPECT_EQ(e.failed, 0);
    for (std::size_t i = 4; i < e.map_t.size(); ++i) {
      EXPECT_LT(e.map_t[i], 0.1) << name << " pair " << i;
      EXPECT_LT(e.map_r[i], 0.3) << name << " pair " << i;
    }
  }
}

}  // namespace
}  // namespace adit
