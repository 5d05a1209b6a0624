// Agreement with evo's definitions on a non-trivial fixture, checked against an independent numpy
// implementation (tests/eval/evo_reference.py, run with Debian's /usr/bin/python3 + python3-numpy
// from the project's setup). evo itself cannot be installed here (no PyPI); the script re-implements
// the evo_ape / evo_rpe (--delta D --delta_unit m, consecutive pairs, pairs on the estimate) and KITTI
// devkit definitions listed in its header, so the C++ and the reference share no code.
#include "eval/evaluate.hpp"
#include "eval/trajectory_io.hpp"
#include "fixtures.hpp"

#include <gtest/gtest.h>

#include <cstdio>
#include <fstream>
#include <map>
#include <random>
#include <sstream>

namespace adit::eval {
namespace {

// Ground truth: a 1.3 km winding roadway at 10 Hz. Estimate: rotated, shifted, 3% scaled, with a
// random-walk drift in position and heading, timestamps jittered by up to 4 ms, 5% of poses missing,
// and some extra poses outside the ground-truth time span.
void writeFixture(const std::string& gt_path, const std::string& est_path) {
  const Trajectory gt = test::windingPath(2600, 10.0);
  std::mt19937 rng(2024);
  std::normal_distribution<double> step(0.0, 0.01), yaw_step(0.0, 0.0004);
  std::uniform_int_distribution<int> jitter_us(-4000, 4000);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  const Eigen::Matrix3d R = Eigen::AngleAxisd(0.6, Eigen::Vector3d(0.2, -0.1, 1).normalized()).toRotationMatrix();
  Trajectory est;
  for (int k = -20; k < 0; ++k) est.push_back({toUtime(10.0 + 0.1 * k), Eigen::Isometry3d::Identity()});
  Eigen::Vector3d drift = Eigen::Vector3d::Zero();
  double yaw = 0.0;
  for (const StampedPose& g : gt) {
    drift += Eigen::Vector3d(step(rng), step(rng), 0.3 * step(rng));
    yaw += yaw_step(rng);
    if (u(rng) < 0.05) continue;
    StampedPose e = g;
    e.utime += jitter_us(rng);
    e.pose.linear() = R * Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitZ()).toRotationMatrix() * g.pose.linear();
    e.pose.translation() = 1.03 * R * (g.pose.translation() + drift) + Eigen::Vector3d(4, -3, 1);
    est.push_back(e);
  }
  writeTum(gt_path, gt);
  writeTum(est_path, est);
}

std::map<std::string, double> runReference(const std::string& gt, const std::string& est, const std::string& mode) {
  const std::string out = test::tempPath("evo_ref_" + mode + ".txt");
  const std::string cmd = "/usr/bin/python3 " + std::string(ADIT_SOURCE_DIR) + "/tests/eval/evo_reference.py " + gt +
                          " " + est + " " + mode + " > " + out;
  std::map<std::string, double> values;
  if (std::system(cmd.c_str()) != 0) return values;
  std::ifstream in(out);
  std::string key;
  double v = 0.0;
  while (in >> key >> v) values[key] = v;
  std::remove(out.c_str());
  return values;
}

void expectStats(const std::map<std::string, double>& ref, const std::string& prefix, const ErrorStats& s, double tol) {
  ASSERT_TRUE(ref.count(prefix + ".count")) << prefix;
  EXPECT_EQ(static_cast<double>(s.count), ref.at(prefix + ".count")) << prefix;
  if (s.count == 0) return;
  EXPECT_NEAR(s.max, ref.at(prefix + ".max"), tol) << prefix;
  EXPECT_NEAR(s.min, ref.at(prefix + ".min"), tol) << prefix;
  EXPECT_NEAR(s.mean, ref.at(prefix + ".mean"), tol) << prefix;
  EXPECT_NEAR(s.median, ref.at(prefix + ".median"), tol) << prefix;
  EXPECT_NEAR(s.rmse, ref.at(prefix + ".rmse"), tol) << prefix;
  EXPECT_NEAR(s.std, ref.at(prefix + ".std"), tol) << prefix;
}

class EvoReference : public ::testing::TestWithParam<const char*> {};

TEST_P(EvoReference, AllNumbersAgree) {
  const std::string mode = GetParam();
  const std::string gt_path = test::tempPath("evo_gt.tum"), est_path = test::tempPath("evo_est.tum");
  writeFixture(gt_path, est_path);
  const std::map<std::string, double> ref = runReference(gt_path, est_path, mode);
  ASSERT_FALSE(ref.empty()) << "reference script failed (needs /usr/bin/python3 with python3-numpy)";

  EvalConfig config;
  config.align = parseAlignMode(mode);
  const EvalResult r = evaluate(readTum(gt_path), readTum(est_path), config);
  ASSERT_TRUE(r.valid);
  EXPECT_EQ(static_cast<double>(r.matched_poses), ref.at("matched"));
  EXPECT_GT(r.matched_poses, 2400u);
  if (mode != "none") {
    EXPECT_NEAR(r.alignment.scale, ref.at("scale"), 1e-9);
  }
  // Metres agree to 1e-9 m (float summation order differs); degrees to 1e-5 deg (the reference
  // takes arccos of the trace, which loses ~1e-8 rad near zero; the C++ uses atan2).
  expectStats(ref, "ape", r.ape_m, 1e-9);
  for (const RpeResult& e : r.rpe) {
    const std::string key = "rpe" + std::to_string(static_cast<int>(e.delta_m));
    expectStats(ref, key + ".trans", e.translation_m, 1e-9);
    expectStats(ref, key + ".rot", e.rotation_deg, 1e-5);
  }
  ASSERT_TRUE(r.drift.available);
  EXPECT_EQ(static_cast<double>(r.drift.segments), ref.at("drift.segments"));
  EXPECT_NEAR(r.drift.translation_percent, ref.at("drift.translation_percent"), 1e-9);
  EXPECT_NEAR(r.drift.rotation_deg_per_m, ref.at("drift.rotation_deg_per_m"), 1e-8);
  EXPECT_NEAR(r.gt_distance_m, ref.at("distance"), 1e-8);
  EXPECT_NEAR(r.end_point.error_m, ref.at("end_point"), 1e-9);
  std::remove(gt_path.c_str());
  std::remove(est_path.c_str());
}

INSTANTIATE_TEST_SUITE_P(Modes, EvoReference, ::testing::Values("none", "se3", "sim3"));

}  // namespace
}  // namespace adit::eval
