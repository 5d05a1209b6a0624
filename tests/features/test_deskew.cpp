// Deskew on a simulated sweep taken at 1.5 m/s while turning: deskewed points lie closer to the true
// geometry than raw ones, with the constant-velocity model, with the IMU, and with both.
#include "core/geometry.hpp"
#include "features/deskew.hpp"
#include "features/feature_extractor.hpp"
#include "synthetic_scans.hpp"

#include <gtest/gtest.h>

#include <cstdio>

namespace adit {
namespace {

// A roadway chamber 35 m long, 4 m wide, 3 m high with two pillars: end walls in range, so motion along
// the roadway shows too.
test::Scene chamber() {
  test::Scene s;
  s.boxes.push_back({{-15.0, -2.0, -1.5}, {20.0, 2.0, 1.5}, true});
  s.boxes.push_back({{6.0, 1.2, -1.5}, {6.5, 2.0, 1.5}, false});
  s.boxes.push_back({{-7.0, -2.0, -1.5}, {-6.4, -1.3, 1.5}, false});
  return s;
}

// Constant motion: 1.5 m/s along the roadway, 0.6 rad/s about an axis tilted off vertical (turning while
// rolling and pitching a little). T_world_lidar(0) = identity, so the end frame is the world frame.
const Eigen::Vector3d kVelocity(1.5, 0.0, 0.0);
const Eigen::Vector3d kAngularVelocity = 0.6 * Eigen::Vector3d(0.2, 0.1, 1.0).normalized();

Eigen::Isometry3d truePose(double t) {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = expRotation(kAngularVelocity * t);
  T.translation() = kVelocity * t;
  return T;
}

struct Errors {
  double mean, p95;
};

Errors geometryError(const test::Scene& scene, const std::vector<LidarPoint>& pts) {
  std::vector<double> d;
  for (const LidarPoint& p : pts) d.push_back(scene.distance(p.p.cast<double>()));
  std::sort(d.begin(), d.end());
  double sum = 0.0;
  for (double x : d) sum += x;
  return {sum / d.size(), d[d.size() * 95 / 100]};
}

MotionPrior truePrior() {
  MotionPrior m;
  m.T_prev_curr = truePose(-0.1).inverse() * truePose(0.0);
  m.dt_s = 0.1;
  m.valid = true;
  return m;
}

// Gyro at 200 Hz covering the sweep, in an IMU frame rotated by R_lidar_imu from the lidar frame.
std::vector<ImuSample> gyro(std::int64_t end_utime, const Eigen::Quaterniond& R_lidar_imu) {
  std::vector<ImuSample> out;
  for (int k = -22; k <= 1; ++k) {
    ImuSample s;
    s.utime = end_utime + 5000 * k;
    s.gyro = R_lidar_imu.conjugate() * kAngularVelocity;  // body rate, expressed in the IMU frame
    s.accel = Eigen::Vector3d(0, 0, 9.81);
    out.push_back(s);
  }
  return out;
}

class Deskew : public ::testing::Test {
 protected:
  void SetUp() override {
    scan_ = test::scanScene(scene_, truePose);
    FeatureConfig off;
    off.deskew.enabled = false;
    raw_ = geometryError(scene_, FeatureExtractor(off).process(scan_, {}, MotionPrior{}).cloud.points);
  }
  Errors run(const std::vector<ImuSample>& imu, const MotionPrior& m, std::int32_t expect_flags,
             const FeatureConfig& cfg = FeatureConfig{}) {
    const FeatureSet f = FeatureExtractor(cfg).process(scan_, imu, m);
    EXPECT_EQ(f.flags & (FeatureSet::kDeskewImu | FeatureSet::kDeskewMotion), expect_flags);
    EXPECT_EQ(f.cloud.deskewed, expect_flags != 0);
    return geometryError(scene_, f.cloud.points);
  }
  const test::Scene scene_ = chamber();
  LidarScan scan_;
  Errors raw_{};
};

// Measured (distance of each point to the nearest true surface): raw mean 61 mm / p95 216 mm; constant
// velocity (exact prior) < 0.01 mm; prior 20% off 12 mm / 43 mm; IMU rotation only 2.5 mm / 0.25 mm (the
// 0.15 m of travel is left, visible only on the end walls, hence mean > p95); IMU + velocity < 0.01 mm;
// times derived from azimuth 0.07 mm / 0.20 mm.
TEST_F(Deskew, ConstantVelocityModelRemovesTheDistortion) {
  const Errors e = run({}, truePrior(), FeatureSet::kDeskewMotion);
  std::printf("raw mean %.1f mm p95 %.1f mm | constant velocity mean %.2f mm p95 %.2f mm\n", raw_.mean * 1e3,
              raw_.p95 * 1e3, e.mean * 1e3, e.p95 * 1e3);
  EXPECT_GT(raw_.mean, 0.02);  // the sweep is visibly distorted
  EXPECT_LT(e.mean, 0.1 * raw_.mean);
  EXPECT_LT(e.p95, 0.005);
}

TEST_F(Deskew, AnImperfectPriorStillHelps) {
  // Odometry 20% off in both speed and turn rate.
  MotionPrior m;
  m.T_prev_curr = Eigen::Isometry3d::Identity();
  m.T_prev_curr.linear() = expRotation(0.8 * kAngularVelocity * 0.1);
  m.T_prev_curr.translation() = 0.8 * kVelocity * 0.1;
  m.dt_s = 0.1;
  m.valid = true;
  const Errors e = run({}, m, FeatureSet::kDeskewMotion);
  std::printf("prior 20%% off: mean %.2f mm p95 %.2f mm\n", e.mean * 1e3, e.p95 * 1e3);
  EXPECT_LT(e.mean, 0.3 * raw_.mean);
  EXPECT_LT(e.p95, 0.3 * raw_.p95);
}

TEST_F(Deskew, ImuRotationAloneRemovesTheRotationalPart) {
  FeatureConfig cfg;
  cfg.deskew.rotation_only_without_prior = true;
  const Errors e = run(gyro(scan_.utime, Eigen::Quaterniond::Identity()), MotionPrior{}, FeatureSet::kDeskewImu, cfg);
  std::printf("IMU rotation only: mean %.2f mm p95 %.2f mm\n", e.mean * 1e3, e.p95 * 1e3);
  EXPECT_LT(e.mean, 0.1 * raw_.mean);
  EXPECT_LT(e.p95, 0.005);
}

// By default a sweep without a motion prior stays raw even with IMU: deskewing its rotation alone would mark
// it deskewed while its translation is left (the vehicle may already move), and downstream would then not
// compensate it.
TEST_F(Deskew, WithoutAPriorTheSweepStaysRawForCompensationDownstream) {
  const Errors e = run(gyro(scan_.utime, Eigen::Quaterniond::Identity()), MotionPrior{}, 0);
  EXPECT_DOUBLE_EQ(e.mean, raw_.mean);
}

TEST_F(Deskew, ImuRotationWithVelocityAndAnExtrinsicRotation) {
  // IMU mounted upside down and turned 90 deg: the configured extrinsic must bring its rates over.
  FeatureConfig cfg;
  cfg.deskew.R_lidar_imu = Eigen::AngleAxisd(M_PI / 2, Eigen::Vector3d::UnitZ()) * Eigen::AngleAxisd(M_PI, Eigen::Vector3d::UnitX());
  const Errors e = run(gyro(scan_.utime, cfg.deskew.R_lidar_imu), truePrior(),
                       FeatureSet::kDeskewImu | FeatureSet::kDeskewMotion, cfg);
  std::printf("IMU + velocity (rotated IMU): mean %.2f mm p95 %.2f mm\n", e.mean * 1e3, e.p95 * 1e3);
  EXPECT_LT(e.mean, 0.1 * raw_.mean);
  EXPECT_LT(e.p95, 0.005);
}

TEST_F(Deskew, DerivedTimesFromAzimuthWorkToo) {
  LidarScan no_time = scan_;
  no_time.has_time = false;
  for (LidarPoint& p : no_time.points) p.dt = 0.0f;
  const FeatureSet f = FeatureExtractor(FeatureConfig{}).process(no_time, {}, truePrior());
  EXPECT_TRUE(f.flags & FeatureSet::kDeskewMotion);
  const Errors e = geometryError(scene_, f.cloud.points);
  std::printf("constant velocity, times from azimuth: mean %.2f mm p95 %.2f mm\n", e.mean * 1e3, e.p95 * 1e3);
  // The azimuth is measured in the moving frame, so a 0.05 rad turn shifts times by up to 0.8 ms: still
  // far below the raw error.
  EXPECT_LT(e.mean, 0.2 * raw_.mean);
}

TEST_F(Deskew, UnusablePriorsAndShortImuLeavePointsAlone) {
  MotionPrior stale = truePrior();
  stale.dt_s = 2.0;  // dropped sweeps: beyond max_prior_dt_s
  const Errors e1 = run({}, stale, 0);
  EXPECT_DOUBLE_EQ(e1.mean, raw_.mean);
  std::vector<ImuSample> late = gyro(scan_.utime, Eigen::Quaterniond::Identity());
  late.erase(late.begin(), late.begin() + 10);  // starts 50 ms into the sweep
  const Errors e2 = run(late, MotionPrior{}, 0);
  EXPECT_DOUBLE_EQ(e2.mean, raw_.mean);
  std::vector<ImuSample> nan_imu = gyro(scan_.utime, Eigen::Quaterniond::Identity());
  nan_imu[3].gyro.x() = std::numeric_limits<double>::quiet_NaN();
  EXPECT_DOUBLE_EQ(run(nan_imu, MotionPrior{}, 0).mean, raw_.mean);
}

TEST(DeskewModel, MotionModelPoseInterpolatesThePreviousInterval) {
  MotionPrior m;
  m.T_prev_curr = truePose(-0.1).inverse() * truePose(0.0);
  m.dt_s = 0.1;
  m.valid = true;
  for (double dt : {-0.1, -0.05, -0.02, 0.0}) {
    const Eigen::Isometry3d expected = truePose(0.0).inverse() * truePose(dt);
    const Eigen::Isometry3d got = features::motionModelPose(m, dt);
    EXPECT_LT((expected.translation() - got.translation()).norm(), 1e-9) << dt;
    EXPECT_LT(rotationAngle(expected.inverse() * got), 1e-9) << dt;
  }
}

}  // namespace
}  // namespace adit
