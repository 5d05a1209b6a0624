// Drift of the whole pipeline on a simulated straight roadway (issue 5: vlp16, 120 s, end-point drift
// below 1 % of the distance travelled).
#include "sim_pipeline.hpp"

#include <gtest/gtest.h>

TEST(DriftSim, RoadwayStraight120sEndPointDriftBelowOnePercent) {
  const auto run = adit::test::runSimPipeline("roadway-straight", 120.0, 1);
  ASSERT_EQ(run.corrected.size(), run.ground_truth.size());
  double distance = 0;
  for (std::size_t i = 1; i < run.ground_truth.size(); ++i)
    distance += (run.ground_truth[i].pose.translation() - run.ground_truth[i - 1].pose.translation()).norm();
  // Both trajectories from their own first pose: the end point's error in the true end frame.
  const Eigen::Isometry3d truth = run.ground_truth.front().pose.inverse() * run.ground_truth.back().pose;
  const Eigen::Isometry3d estimate = run.corrected.front().pose.inverse() * run.corrected.back().pose;
  const double error = (truth.inverse() * estimate).translation().norm();
  std::printf("roadway-straight 120 s: %.1f m travelled, end-point error %.3f m (%.2f %%), %zu loops\n", distance,
              error, 100.0 * error / distance, run.loops.size());
  EXPECT_GT(distance, 120.0);
  EXPECT_LT(error, 0.01 * distance);
  EXPECT_EQ(run.false_loops, 0);
}
