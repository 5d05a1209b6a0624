// PNG plots through /usr/bin/python3 + matplotlib (installed by the project's setup).
#include "eval/plot.hpp"
#include "fixtures.hpp"

#include <gtest/gtest.h>

#include <cstdio>
#include <fstream>
#include <random>

namespace adit::eval {
namespace {

// A PNG starts with its 8-byte signature; a real plot is tens of kB.
void expectPng(const std::string& path, std::size_t min_bytes) {
  std::ifstream in(path, std::ios::binary);
  ASSERT_TRUE(in.good()) << path;
  std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  ASSERT_GE(bytes.size(), 8u);
  EXPECT_EQ(bytes.substr(0, 8), std::string("\x89PNG\r\n\x1a\n", 8));
  EXPECT_GT(bytes.size(), min_bytes);
}

EvalResult noisyResult() {
  const Trajectory gt = test::windingPath(400);
  Trajectory est = gt;
  std::mt19937 rng(1);
  std::normal_distribution<double> n(0.0, 0.1);
  for (StampedPose& p : est) p.pose.translation() += Eigen::Vector3d(n(rng), n(rng), n(rng));
  return evaluate(gt, est);
}

TEST(Plot, ScriptIsFoundNextToTheBinary) {
  const std::string script = findPlotScript();
  EXPECT_EQ(script, std::string(ADIT_BIN_DIR) + "/../share/adit/plot_trajectory.py");
}

TEST(Plot, TrajectoryPng) {
  const std::string png = test::tempPath("traj.png");
  const PlotResult r = plotTrajectory(noisyResult(), png);
  ASSERT_TRUE(r.ok) << r.message;
  expectPng(png, 20000);
  std::remove(png.c_str());
}

TEST(Plot, MapTopViewFromPointsAndFromPcd) {
  // A 40 m x 4 m roadway: floor and two walls.
  std::vector<Eigen::Vector3f> points;
  std::mt19937 rng(5);
  std::uniform_real_distribution<float> u(0.f, 1.f);
  for (int i = 0; i < 30000; ++i) {
    const float x = 40.f * u(rng), s = u(rng);
    if (i % 3 == 0) points.emplace_back(x, 4.f * s - 2.f, -1.5f);
    else points.emplace_back(x, i % 3 == 1 ? -2.f : 2.f, 3.f * s - 1.5f);
  }
  points.emplace_back(std::nanf(""), 0.f, 0.f);  // ignored
  const std::string png = test::tempPath("map.png");
  const PlotResult r = plotMapTopView(points, png, test::line(41, 1.0));
  ASSERT_TRUE(r.ok) << r.message;
  expectPng(png, 10000);
  std::remove(png.c_str());

  const std::string pcd = test::tempPath("map.pcd");
  {
    std::ofstream out(pcd);
    out << "# .PCD v0.7\nVERSION 0.7\nFIELDS x y z intensity\nSIZE 4 4 4 4\nTYPE F F F F\nCOUNT 1 1 1 1\n"
        << "WIDTH 1000\nHEIGHT 1\nVIEWPOINT 0 0 0 1 0 0 0\nPOINTS 1000\nDATA ascii\n";
    for (int i = 0; i < 1000; ++i) out << points[static_cast<std::size_t>(i)].transpose() << " 1\n";
  }
  const PlotResult from_pcd = plotMapTopViewFromPcd(pcd, png);
  ASSERT_TRUE(from_pcd.ok) << from_pcd.message;
  expectPng(png, 5000);
  std::remove(png.c_str());
  std::remove(pcd.c_str());
}

TEST(Plot, MissingPythonOrBadInputIsAnErrorNotACrash) {
  PlotOptions no_python;
  no_python.python = "/nonexistent/python3";
  const PlotResult r = plotTrajectory(noisyResult(), test::tempPath("x.png"), no_python);
  EXPECT_FALSE(r.ok);
  EXPECT_NE(r.message.find("python3-matplotlib"), std::string::npos) << r.message;

  EXPECT_FALSE(plotTrajectory(EvalResult{}, test::tempPath("x.png")).ok);
  EXPECT_FALSE(plotMapTopView({}, test::tempPath("x.png")).ok);
  EXPECT_FALSE(plotMapTopViewFromPcd("/nonexistent.pcd", test::tempPath("x.png")).ok);
  const std::string garbage = test::tempPath("garbage.pcd");
  std::ofstream(garbage) << "VERSION 0.7\nFIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nCOUNT 1 1 1\nWIDTH 100\n"
                            "HEIGHT 1\nPOINTS 100\nDATA binary\nshort";
  const PlotResult corrupt = plotMapTopViewFromPcd(garbage, test::tempPath("x.png"));
  EXPECT_FALSE(corrupt.ok);
  EXPECT_FALSE(corrupt.message.empty());
  std::remove(garbage.c_str());

  // The script's own failure (unwritable output) comes back with its stderr.
  const PlotResult unwritable = plotTrajectory(noisyResult(), "/nonexistent/dir/x.png");
  EXPECT_FALSE(unwritable.ok);
  EXPECT_NE(unwritable.message.find("plot failed"), std::string::npos) << unwritable.message;
}

}  // namespace
}  // namespace adit::eval
