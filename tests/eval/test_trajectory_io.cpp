// TUM / KITTI readers and writers, KITTI calib conversion, malformed files.
#include "eval/trajectory_io.hpp"
#include "fixtures.hpp"

#include <gtest/gtest.h>

#include <cstdio>
#include <fstream>

namespace adit::eval {
namespace {

const std::string kKitti = std::string(ADIT_SHARED_DATA_DIR) + "/kitti_mini";

void writeFile(const std::string& path, const std::string& text) {
  std::ofstream(path) << text;
}

// Expect `fn` to throw a runtime_error whose message contains `needle`.
template <class Fn>
void expectErrorContaining(Fn fn, const std::string& needle) {
  try {
    fn();
    ADD_FAILURE() << "no error, expected one containing '" << needle << "'";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find(needle), std::string::npos) << e.what();
  }
}

void expectSamePoses(const Trajectory& a, const Trajectory& b, double tol) {
  ASSERT_EQ(a.size(), b.size());
  for (std::size_t i = 0; i < a.size(); ++i) {
    EXPECT_EQ(a[i].utime, b[i].utime);
    EXPECT_NEAR((a[i].pose.matrix() - b[i].pose.matrix()).cwiseAbs().maxCoeff(), 0.0, tol);
  }
}

TEST(TumFile, RoundTrip) {
  Trajectory t = test::windingPath(50, 1317384506.40);  // large epoch stamps survive
  t[3].pose.linear() = Eigen::AngleAxisd(3.0, Eigen::Vector3d(1, 1, 0).normalized()).toRotationMatrix();
  const std::string path = test::tempPath("rt.tum");
  writeTum(path, t);
  expectSamePoses(readTum(path), t, 1e-8);
  EXPECT_EQ(detectFormat(path), TrajectoryFormat::kTum);
  std::ifstream tmp(path + ".tmp");
  EXPECT_FALSE(tmp.good());  // the temp file was renamed away
  std::remove(path.c_str());
}

TEST(TumFile, CommentsBlankLinesAndQuaternionOrder) {
  const std::string path = test::tempPath("q.tum");
  // qx qy qz qw = 90 deg about z; unnormalised on purpose.
  writeFile(path, "# header\n\n1.5 1 2 3 0 0 1.4142135623730951 1.4142135623730951\n");
  const Trajectory t = readTum(path);
  ASSERT_EQ(t.size(), 1u);
  EXPECT_EQ(t[0].utime, 1500000);
  EXPECT_NEAR((t[0].pose.linear() * Eigen::Vector3d::UnitX() - Eigen::Vector3d::UnitY()).norm(), 0.0, 1e-12);
  EXPECT_NEAR((t[0].pose.translation() - Eigen::Vector3d(1, 2, 3)).norm(), 0.0, 0.0);
  std::remove(path.c_str());
}

TEST(TumFile, MalformedLinesNameTheLine) {
  const std::string path = test::tempPath("bad.tum");
  writeFile(path, "0 0 0 0 0 0 0 1\n0.1 0 0 0 0 0 1\n");
  expectErrorContaining([&] { readTum(path); }, ":2: expected 8 numbers");
  writeFile(path, "# c\n0 0 0 0 0 0 0 1\n0.1 0 abc 0 0 0 0 1\n");
  expectErrorContaining([&] { readTum(path); }, ":3: 'abc' is not a number");
  writeFile(path, "0 0 0 0 0 0 0 0\n");
  expectErrorContaining([&] { readTum(path); }, ":1: quaternion has zero norm");
  writeFile(path, "0 nan 0 0 0 0 0 1\n");
  expectErrorContaining([&] { readTum(path); }, ":1:");
  writeFile(path, "0 1e999 0 0 0 0 0 1\n");
  expectErrorContaining([&] { readTum(path); }, ":1:");
  writeFile(path, "");
  EXPECT_TRUE(readTum(path).empty());
  expectErrorContaining([&] { detectFormat(path); }, "no poses");
  writeFile(path, "1 2 3\n");
  expectErrorContaining([&] { detectFormat(path); }, ":1: neither TUM");
  std::remove(path.c_str());
  expectErrorContaining([&] { readTum("/nonexistent/x.tum"); }, "cannot open");
  expectErrorContaining([&] { readTum("/tmp"); }, "not a regular file");  // a directory: error, no crash
}

TEST(KittiFile, RoundTripWithTimes) {
  const Trajectory t = test::windingPath(40, 0.0);
  const std::string path = test::tempPath("rt.kitti");
  writeKitti(path, t);
  EXPECT_EQ(detectFormat(path), TrajectoryFormat::kKitti);
  expectSamePoses(readKitti(path), t, 1e-11);  // default 0.1 s per pose = windingPath's stamps
  std::vector<double> times;
  for (int i = 0; i < 40; ++i) times.push_back(5.0 + 0.2 * i);
  const Trajectory timed = readKitti(path, times);
  EXPECT_EQ(timed[39].utime, toUtime(5.0 + 0.2 * 39));
  expectErrorContaining([&] { readKitti(path, std::vector<double>(10, 0.0)); }, ":11: more poses than timestamps");
  std::remove(path.c_str());
}

TEST(KittiFile, MalformedLinesNameTheLine) {
  const std::string path = test::tempPath("bad.kitti");
  writeFile(path, "1 0 0 0 0 1 0 0 0 0 1 0\n1 0 0 0 0 1 0 0 0 0 1\n");
  expectErrorContaining([&] { readKitti(path); }, ":2: expected 12 numbers");
  writeFile(path, "1 0 0 0 0 1 0 0 0 0 5 0\n");  // not a rotation
  expectErrorContaining([&] { readKitti(path); }, ":1: the 3x3 block is not a rotation");
  writeFile(path, "-1 0 0 0 0 1 0 0 0 0 1 0\n");  // reflection
  expectErrorContaining([&] { readKitti(path); }, ":1:");
  writeFile(path, "P0: 1 2 3\n");
  expectErrorContaining([&] { readKittiVeloToCam(path); }, "no 'Tr:' line");
  writeFile(path, "Tr: 1 0 0\n");
  expectErrorContaining([&] { readKittiVeloToCam(path); }, ":1: Tr needs 12 numbers");
  std::remove(path.c_str());
}

TEST(KittiCalib, Sequence01GroundTruthInLidarFrameDrivesAlongPlusX) {
  const Eigen::Isometry3d Tr = readKittiVeloToCam(kKitti + "/sequences/01/calib.txt");
  // Velodyne x (forward) maps to camera z (forward).
  EXPECT_GT((Tr.linear() * Eigen::Vector3d::UnitX()).z(), 0.99);
  const std::vector<double> times = readTimes(kKitti + "/sequences/01/times.txt");
  const Trajectory cam = readKitti(kKitti + "/poses/01.txt", times);
  ASSERT_EQ(cam.size(), 10u);
  EXPECT_EQ(cam[1].utime, toUtime(1.037595e-01));
  const Trajectory velo = cameraToLidar(cam, Tr);
  EXPECT_NEAR((velo[0].pose.matrix() - Eigen::Matrix4d::Identity()).norm(), 0.0, 1e-6);
  for (std::size_t k = 1; k < velo.size(); ++k) {
    // Motion between scans seen from the previous lidar pose: the highway car moves ~1 m per scan
    // forward (+x of the lidar); sideways and vertical motion are small. (In the world frame the
    // heading turns left over these frames, so world x/y are not the test.)
    const Eigen::Vector3d step = (velo[k - 1].pose.inverse() * velo[k].pose).translation();
    EXPECT_GT(step.x(), 0.8) << "frame " << k;
    EXPECT_LT(step.x(), 1.4) << "frame " << k;
    EXPECT_LT(std::abs(step.y()), 0.1 * step.x()) << "frame " << k;
    EXPECT_LT(std::abs(step.z()), 0.1 * step.x()) << "frame " << k;
    // In the camera frame the same motion is along +z.
    EXPECT_GT((cam[k - 1].pose.inverse() * cam[k].pose).translation().z(), 0.8);
  }
  expectSamePoses(lidarToCamera(velo, Tr), cam, 1e-9);
}

}  // namespace
}  // namespace adit::eval
