// The whole front end (lib/sim vlp16 -> FeatureExtractor -> odometry -> mapping) on a simulated roadway:
// end-point drift on roadway-straight. (The featureless world's degenerate zone is in test_sim_featureless.cpp;
// the degeneracy prior on synthetic corridors in test_degeneracy.cpp.)
#include "core/geometry.hpp"
#include "mapping/scan_to_map.hpp"
#include "odometry/scan_to_scan.hpp"
#include "sim_run.hpp"

#include <gtest/gtest.h>

#include <cstdio>

namespace adit {
namespace {

struct DriveError {
  double distance = 0.0;        // travelled (m, ground truth)
  Eigen::Vector3d end_error;    // end-point error in the frame of the true end pose (m)
  int degenerate_sweeps = 0;    // mapping flagged kDegenerateTranslation
  int failed_sweeps = 0;
};

DriveError runPipeline(const test::SimRun& run, bool degeneracy_prior) {
  ScanToScanConfig oc;
  oc.registration.degeneracy_prior = degeneracy_prior;
  MapperConfig mc;
  mc.registration.degeneracy_prior = degeneracy_prior;
  ScanToScanOdometry odom(oc);
  ScanToMapMapper mapper(mc);
  DriveError d;
  Eigen::Isometry3d first = Eigen::Isometry3d::Identity(), last = first;
  for (std::size_t i = 0; i < run.features.size(); ++i) {
    const PoseEstimate m = mapper.process(run.features[i], odom.process(run.features[i]));
    if (i == 0) first = m.pose;
    last = m.pose;
    if (m.flags & PoseEstimate::kDegenerateTranslation) ++d.degenerate_sweeps;
    if (m.flags & PoseEstimate::kRegistrationFailed) ++d.failed_sweeps;
    if (i > 0) d.distance += (run.truth[i].pose.translation() - run.truth[i - 1].pose.translation()).norm();
  }
  const Eigen::Isometry3d truth = run.truth.front().pose.inverse() * run.truth.back().pose;
  d.end_error = (truth.inverse() * (first.inverse() * last)).translation();
  return d;
}

TEST(SimDrive, RoadwayStraightDriftBelowOnePercent) {
  // 20 s: 2 s standing, then ~20 m at 1.3 m/s (measured 0.48% end-point error, 0.59% before the edge noise floor).
  const test::SimRun run = test::simulateRun("roadway-straight", "vlp16", 20.0);
  const DriveError d = runPipeline(run, true);
  std::printf("roadway-straight %zu sweeps, %.1f m: end error %.3f m (%.2f%%), (%.3f %.3f %.3f), failed %d\n",
              run.features.size(), d.distance, d.end_error.norm(), 100.0 * d.end_error.norm() / d.distance,
              d.end_error.x(), d.end_error.y(), d.end_error.z(), d.failed_sweeps);
  EXPECT_EQ(d.failed_sweeps, 0);
  EXPECT_LT(d.end_error.norm(), 0.01 * d.distance);
}

}  // namespace
}  // namespace adit
