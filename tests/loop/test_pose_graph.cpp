// Pose graph: a drifting square loop closed by one loop edge, and the g2o round trip.
#include "loop/pose_graph.hpp"

#include "loop/graph_merge.hpp"

#include "core/geometry.hpp"

#include <gtest/gtest.h>

#include <dirent.h>

#include <cmath>
#include <cstdio>
#include <sstream>
#include <thread>

using namespace adit;

namespace {

Eigen::Isometry3d pose(double x, double y, double yaw) {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  T.translation() = Eigen::Vector3d(x, y, 0.0);
  return T;
}

// 4 sides of 20 m with a node per metre, turning 90 deg at each corner: 80 nodes, node 80 = node 0.
std::vector<Eigen::Isometry3d> squareTruth() {
  std::vector<Eigen::Isometry3d> truth{Eigen::Isometry3d::Identity()};
  for (int side = 0; side < 4; ++side)
    for (int i = 0; i < 20; ++i) {
      Eigen::Isometry3d step = pose(1.0, 0.0, i == 19 ? M_PI / 2 : 0.0);
      truth.push_back(truth.back() * step);
    }
  return truth;
}

double rmsPositionError(const std::vector<Eigen::Isometry3d>& a, const std::vector<Eigen::Isometry3d>& b) {
  double sum = 0;
  for (std::size_t i = 0; i < a.size(); ++i) sum += (a[i].translation() - b[i].translation()).squaredNorm();
  return std::sqrt(sum / static_cast<double>(a.size()));
}

Matrix6d information(double sigma_t, double sigma_r) {
  Matrix6d info = Matrix6d::Zero();
  info.diagonal() << 1 / (sigma_t * sigma_t), 1 / (sigma_t * sigma_t), 1 / (sigma_t * sigma_t),
      1 / (sigma_r * sigma_r), 1 / (sigma_r * sigma_r), 1 / (sigma_r * sigma_r);
  return info;
}

// Odometry that over-turns by 0.15 deg per 1 m step (a loop cannot fix a scale error, so none here).
PoseGraph driftingSquare(const std::vector<Eigen::Isometry3d>& truth) {
  PoseGraph g;
  g.addNode(truth[0]);
  for (std::size_t i = 1; i < truth.size(); ++i) {
    Eigen::Isometry3d step = truth[i - 1].inverse() * truth[i];
    step.linear() = step.linear() * Eigen::AngleAxisd(0.15 * M_PI / 180, Eigen::Vector3d::UnitZ()).toRotationMatrix();
    const int id = g.addNode(g.pose(static_cast<int>(i) - 1) * step);
    g.addOdometryEdge(id - 1, id, step, information(0.02, 0.002));
  }
  return g;
}

}  // namespace

TEST(PoseGraph, OneLoopEdgeRemovesMostOfTheDriftOfASquare) {
  const auto truth = squareTruth();
  PoseGraph g = driftingSquare(truth);
  const double before = rmsPositionError(g.poses(), truth);
  // The last node is back at the start: loop edge node 0 -> node 80 with the true relative pose.
  g.addLoopEdge(0, 80, truth[0].inverse() * truth[80], information(0.05, 0.01));
  const PoseGraphReport report = g.optimize();
  const double after = rmsPositionError(g.poses(), truth);
  std::printf("square loop RMS position error: %.3f m before, %.3f m after (%d iterations)\n", before, after,
              report.iterations);
  EXPECT_TRUE(report.solved);
  EXPECT_GT(before, 1.0);      // the drift is real: several metres
  EXPECT_LT(after, 0.3 * before);
  EXPECT_LT((g.pose(80).translation() - g.pose(0).translation()).norm(), 0.3);
  EXPECT_LT((g.pose(0).translation() - truth[0].translation()).norm(), 1e-9);  // first node fixed
}

TEST(PoseGraph, RobustLoopEdgeLimitsTheDamageOfAGrossOutlier) {
  const auto truth = squareTruth();
  PoseGraph good = driftingSquare(truth), bad = driftingSquare(truth), plain = driftingSquare(truth);
  good.addLoopEdge(0, 80, Eigen::Isometry3d::Identity(), information(0.05, 0.01));
  bad.addLoopEdge(0, 80, Eigen::Isometry3d::Identity(), information(0.05, 0.01));
  bad.addLoopEdge(10, 50, pose(0.0, 0.0, 0.0), information(0.05, 0.01));  // says 10 and 50 coincide: false
  plain.addLoopEdge(0, 80, Eigen::Isometry3d::Identity(), information(0.05, 0.01));
  plain.addEdge({10, 50, pose(0.0, 0.0, 0.0), information(0.05, 0.01), false});  // same false loop, no robust loss
  good.optimize();
  bad.optimize();
  plain.optimize();
  const double good_err = rmsPositionError(good.poses(), truth), bad_err = rmsPositionError(bad.poses(), truth);
  const double plain_err = rmsPositionError(plain.poses(), truth);
  std::printf("false loop 20 m off: %.3f m robust, %.3f m plain least squares (no false loop: %.3f m)\n", bad_err,
              plain_err, good_err);
  EXPECT_LT(bad_err, 0.5 * plain_err);
}

namespace {

// This process's threads (Linux: one entry per thread in /proc/self/task).
int threadCount() {
  int n = 0;
  if (DIR* dir = ::opendir("/proc/self/task")) {
    while (const dirent* entry = ::readdir(dir)) n += entry->d_name[0] != '.' ? 1 : 0;
    ::closedir(dir);
  }
  return n;
}

// `laps` laps of a ring of `per_lap` nodes, each node tied by a loop edge to the same place one lap before: a
// lattice whose sparse Cholesky factor is large and dense enough for the supernodal path.
PoseGraph lattice(int laps, int per_lap) {
  PoseGraph g;
  const double step_yaw = 2 * M_PI / per_lap;
  const Eigen::Isometry3d step = pose(1.0, 0.0, step_yaw);
  Eigen::Isometry3d drifting_step = step;
  drifting_step.linear() = drifting_step.linear() * Eigen::AngleAxisd(0.002, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  g.addNode(Eigen::Isometry3d::Identity());
  for (int i = 1; i < laps * per_lap; ++i) {
    const int id = g.addNode(g.pose(i - 1) * drifting_step);
    g.addOdometryEdge(id - 1, id, step, information(0.02, 0.002));
    if (i >= per_lap) g.addLoopEdge(i - per_lap, i, Eigen::Isometry3d::Identity(), information(0.05, 0.01));
  }
  return g;
}

}  // namespace

// Ceres is told to use one thread, but the sparse Cholesky under it (CHOLMOD) opens OpenMP regions on a large
// factorisation, which would leave a pool of one thread per core in the process for good (a live loop closer
// grew 4 -> 7 threads late in a two-hour soak). Solved on a worker thread as the loop closer does, then on this
// one: no thread is left behind either way.
TEST(PoseGraph, ALargeGraphIsSolvedOnTheCallingThreadAlone) {
  PoseGraph on_worker = lattice(10, 100), here = on_worker;
  const int before = threadCount();
  PoseGraphReport worker_report;
  std::thread worker([&] { worker_report = on_worker.optimize(); });
  worker.join();
  EXPECT_TRUE(worker_report.solved);
  EXPECT_EQ(threadCount(), before);
  EXPECT_TRUE(here.optimize().solved);
  EXPECT_EQ(threadCount(), before);
  std::printf("threads before %d, after %d (%d nodes, %zu edges)\n", before, threadCount(), here.size(),
              here.edges().size());
}

TEST(PoseGraph, G2oRoundTripKeepsPosesEdgesAndInformation) {
  const auto truth = squareTruth();
  PoseGraph g = driftingSquare(truth);
  Matrix6d info = information(0.05, 0.01);
  info(0, 4) = info(4, 0) = 3.0;  // a correlated term survives too
  g.addLoopEdge(0, 80, truth[0].inverse() * truth[80], info);
  g.optimize();
  std::stringstream text;
  writeG2o(g, text);
  PoseGraph loaded;
  ASSERT_TRUE(readG2o(text, loaded));
  ASSERT_EQ(loaded.size(), g.size());
  ASSERT_EQ(loaded.edges().size(), g.edges().size());
  for (int i = 0; i < g.size(); ++i) EXPECT_TRUE(loaded.pose(i).isApprox(g.pose(i), 1e-12));
  for (std::size_t e = 0; e < g.edges().size(); ++e) {
    EXPECT_EQ(loaded.edges()[e].from, g.edges()[e].from);
    EXPECT_EQ(loaded.edges()[e].robust, g.edges()[e].robust);
    EXPECT_TRUE(loaded.edges()[e].T_from_to.isApprox(g.edges()[e].T_from_to, 1e-12));
    EXPECT_TRUE(loaded.edges()[e].information.isApprox(g.edges()[e].information, 1e-12));
  }
  // Through a file (written atomically) and back, and a malformed file is refused without touching the graph.
  const std::string path = ::testing::TempDir() + "loop_graph.g2o";
  ASSERT_TRUE(saveG2o(g, path));
  PoseGraph from_file;
  ASSERT_TRUE(loadG2o(path, from_file));
  EXPECT_EQ(from_file.size(), g.size());
  std::stringstream broken("VERTEX_SE3:QUAT 0 0 0 0 0 0 0 1\nEDGE_SE3:QUAT 0 7 1 2\n");
  EXPECT_FALSE(readG2o(broken, from_file));
  EXPECT_EQ(from_file.size(), g.size());
}

namespace {

Matrix6d covariance(double sigma_t, double sigma_r) {
  Matrix6d c = Matrix6d::Zero();
  c.diagonal() << sigma_t * sigma_t, sigma_t * sigma_t, sigma_t * sigma_t, sigma_r * sigma_r, sigma_r * sigma_r,
      sigma_r * sigma_r;
  return c;
}

}  // namespace

// Nodes merged out of an optimised graph: no kept pose moves, the run between two kept nodes becomes one edge
// that measures their current relative pose with the chain's summed covariance, and loops of merged nodes go.
TEST(GraphMerge, ARunOfNodesBecomesOneEdgeAndNoPoseMoves) {
  const std::vector<Eigen::Isometry3d> truth = squareTruth();
  PoseGraph graph;
  OdometryChain chain;
  Eigen::Isometry3d odometry = truth[0];
  for (std::size_t k = 0; k < truth.size(); ++k) {
    Eigen::Isometry3d step = k == 0 ? Eigen::Isometry3d::Identity() : truth[k - 1].inverse() * truth[k];
    step = step * pose(0.0, 0.0, 0.01);  // a heading drift per step
    odometry = k == 0 ? truth[0] : odometry * step;
    const Matrix6d c = covariance(0.02 + 0.001 * static_cast<double>(k), 0.002);
    chain.add(odometry, c);
    graph.addNode(odometry);
    if (k > 0) graph.addOdometryEdge(static_cast<int>(k) - 1, static_cast<int>(k), step, c.inverse());
  }
  const int last = graph.size() - 1;
  graph.addLoopEdge(0, last, Eigen::Isometry3d::Identity(), information(0.05, 0.01));   // the square closes
  graph.addLoopEdge(10, 50, truth[10].inverse() * truth[50], information(0.05, 0.01));  // across it
  ASSERT_TRUE(graph.optimize().solved);

  std::vector<bool> keep(static_cast<std::size_t>(graph.size()), true);
  for (int k = 20; k < 60; ++k) keep[static_cast<std::size_t>(k)] = false;  // removes node 50 and its loop
  const MergedGraph merged = mergeOutNodes(graph, chain, keep);
  ASSERT_EQ(merged.graph.size(), graph.size() - 40);
  ASSERT_EQ(merged.chain.size(), merged.graph.size());
  EXPECT_EQ(merged.new_index[19], 19);
  EXPECT_EQ(merged.new_index[30], -1);
  EXPECT_EQ(merged.new_index[60], 20);
  for (int k = 0; k < graph.size(); ++k) {
    const int n = merged.new_index[static_cast<std::size_t>(k)];
    if (n < 0) continue;
    EXPECT_TRUE(merged.graph.pose(n).isApprox(graph.pose(k), 1e-12)) << k;
    EXPECT_TRUE(merged.chain.pose(n).isApprox(chain.pose(k), 1e-12)) << k;
  }
  // 19 + 20 odometry edges kept, one across the run, the square's loop; the loop 10 -> 50 went with node 50.
  int loops = 0, across = 0;
  for (const PoseGraphEdge& e : merged.graph.edges()) {
    loops += e.robust ? 1 : 0;
    if (e.from == 19 && e.to == 20) {
      ++across;
      EXPECT_TRUE(e.T_from_to.isApprox(graph.pose(19).inverse() * graph.pose(60), 1e-12));
      EXPECT_TRUE(e.information.inverse().isApprox(chain.covarianceBetween(19, 60), 1e-9));
    }
  }
  EXPECT_EQ(loops, 1);
  EXPECT_EQ(across, 1);
  EXPECT_EQ(static_cast<int>(merged.graph.edges().size()), 19 + 20 + 1 + 1);
  // The chain's covariance across the merged run is the old one.
  EXPECT_TRUE(merged.chain.covarianceBetween(10, 25).isApprox(chain.covarianceBetween(10, 65), 1e-9));

}
