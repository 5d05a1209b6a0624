// SharedAppendVector (core/shared_append_vector.hpp), the storage that lets a loop job's snapshot of the pose
// graph and odometry chain share their elements with the loop closer's: a copy keeps exactly what it had, whatever
// either side appends afterwards, across chunk boundaries and while another thread reads it.
#include "core/shared_append_vector.hpp"
#include "loop/odometry_chain.hpp"
#include "loop/pose_graph.hpp"

#include <gtest/gtest.h>

#include <thread>

namespace adit {
namespace {

using Vec = SharedAppendVector<int>;

Vec counting(int n) {
  Vec v;
  for (int i = 0; i < n; ++i) v.push_back(i);
  return v;
}

void expectCounting(const Vec& v, int n) {
  ASSERT_EQ(v.size(), static_cast<std::size_t>(n));
  int expected = 0;
  for (int x : v) ASSERT_EQ(x, expected++);
  ASSERT_EQ(expected, n);
}

TEST(SharedAppendVector, ACopyKeepsWhatItHadWhileTheOriginalGrows) {
  const int n = static_cast<int>(Vec::kChunk) + 7;  // a full chunk and a partial one, both shared
  Vec original = counting(n);
  const Vec snapshot = original;
  for (int i = n; i < 3 * n; ++i) original.push_back(i);  // fills the shared partial chunk's copy, then more
  expectCounting(snapshot, n);
  expectCounting(original, 3 * n);
  EXPECT_EQ(original.back(), 3 * n - 1);
  EXPECT_EQ(snapshot.back(), n - 1);
}

TEST(SharedAppendVector, AppendsToACopyNeverReachTheOriginal) {
  const Vec original = counting(10);
  Vec copy = original;
  copy.push_back(-1);
  expectCounting(original, 10);
  EXPECT_EQ(copy.size(), 11u);
  EXPECT_EQ(copy[10], -1);
  EXPECT_EQ(copy[9], 9);
}

TEST(SharedAppendVector, ExactChunkBoundariesAndEmpty) {
  Vec empty;
  EXPECT_TRUE(empty.empty());
  EXPECT_TRUE(empty.begin() == empty.end());
  for (int n : {1, static_cast<int>(Vec::kChunk) - 1, static_cast<int>(Vec::kChunk), static_cast<int>(Vec::kChunk) + 1}) {
    Vec v = counting(n);
    const Vec snapshot = v;
    v.push_back(n);
    expectCounting(snapshot, n);
    expectCounting(v, n + 1);
  }
}

TEST(SharedAppendVector, ASnapshotIsReadOnAnotherThreadWhileTheOriginalAppends) {
  Vec original = counting(100);
  for (int round = 0; round < 20; ++round) {
    Vec snapshot = original;
    const int n = static_cast<int>(snapshot.size());
    std::thread reader([s = std::move(snapshot), n] { expectCounting(s, n); });
    for (int i = 0; i < 300; ++i) original.push_back(static_cast<int>(original.size()));
    reader.join();
  }
  expectCounting(original, 100 + 20 * 300);
}

// What the loop closer relies on: a job's copy of the graph and chain answers as the originals did when copied.
TEST(SharedAppendVector, PoseGraphAndChainCopiesAreSnapshots) {
  PoseGraph graph;
  OdometryChain chain;
  const Eigen::Isometry3d step(Eigen::Translation3d(1.0, 0.0, 0.0));
  graph.addNode(Eigen::Isometry3d::Identity());
  chain.add(Eigen::Isometry3d::Identity(), Matrix6d::Zero());
  for (int k = 1; k < 700; ++k) {
    graph.addNode(graph.pose(k - 1) * step);
    graph.addOdometryEdge(k - 1, k, step, Matrix6d::Identity() * k);
    chain.add(chain.pose(k - 1) * step, Matrix6d::Identity() * 1e-4 * k);
  }
  const PoseGraph graph_copy = graph;
  const OdometryChain chain_copy = chain;
  const Matrix6d covariance = chain.covarianceBetween(10, 699);
  for (int k = 700; k < 1500; ++k) {
    graph.addNode(graph.pose(k - 1) * step);
    graph.addOdometryEdge(k - 1, k, step, Matrix6d::Identity());
    chain.add(chain.pose(k - 1) * step, Matrix6d::Identity());
  }
  graph.addLoopEdge(0, 1499, Eigen::Isometry3d::Identity(), Matrix6d::Identity());
  ASSERT_EQ(graph_copy.edges().size(), 699u);
  EXPECT_EQ(graph_copy.edges()[698].to, 699);
  EXPECT_DOUBLE_EQ(graph_copy.edges()[600].information(0, 0), 601.0);
  ASSERT_EQ(chain_copy.size(), 700);
  EXPECT_TRUE(chain_copy.covarianceBetween(10, 699).isApprox(covariance, 0.0));
  EXPECT_EQ(graph.edges().size(), 1500u);
}

}  // namespace
}  // namespace adit
