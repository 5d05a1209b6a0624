// The whole front end (lib/sim vlp16 -> FeatureExtractor -> odometry -> mapping) through the featureless world,
// a smooth arched tunnel with nothing along its axis once both dead ends are out of range: the axis is
// unobservable there and only the degeneracy prior (constant velocity along the degenerate direction) keeps
// the estimate moving with the robot. Compared with the prior disabled, which is what "doing nothing" means.
//
// The feature stage's range is cut to 30 m so the degenerate zone starts ~30 m into the tunnel instead of
// ~100 m: the same geometry (both ends beyond range, smooth arch around) at a third of the simulated time.
#include "mapping/scan_to_map.hpp"
#include "odometry/scan_to_scan.hpp"
#include "sim_run.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>

namespace adit {
namespace {

constexpr double kRange = 30.0;  // m, feature-stage range (see above)

struct AxialDrift {
  double zone_start = 0.0;      // m along the axis (from the first sweep) where both ends left range
  double zone_length = 0.0;     // m driven inside the zone
  double max_error = 0.0;       // largest |axial error| inside the zone (m)
  double end_error = 0.0;       // axial error at the last sweep (m, estimate - truth)
  double degenerate_fraction = 0.0;  // zone sweeps the mapper flagged kDegenerateTranslation
};

AxialDrift runPipeline(const test::SimRun& run, bool degeneracy_prior) {
  ScanToScanConfig oc;
  oc.registration.degeneracy_prior = degeneracy_prior;
  MapperConfig mc;
  mc.registration.degeneracy_prior = degeneracy_prior;
  ScanToScanOdometry odom(oc);
  ScanToMapMapper mapper(mc);
  AxialDrift d;
  const Eigen::Isometry3d truth0 = run.truth.front().pose;
  Eigen::Isometry3d first = Eigen::Isometry3d::Identity();
  const double tunnel_start = truth0.translation().x();  // metres from the dead end at x = 0 (sim layout)
  int zone_sweeps = 0, degenerate = 0;
  double start_x = -1.0, x = 0.0;
  for (std::size_t i = 0; i < run.features.size(); ++i) {
    const PoseEstimate m = mapper.process(run.features[i], odom.process(run.features[i]));
    if (i == 0) first = m.pose;
    x = (truth0.inverse() * run.truth[i].pose).translation().x();
    const double error = (first.inverse() * m.pose).translation().x() - x;
    // Inside the zone: both dead ends (x = 0 and the far one, 320 m) farther than the range.
    if (tunnel_start + x < kRange) continue;
    if (start_x < 0.0) start_x = x;
    ++zone_sweeps;
    if (m.flags & PoseEstimate::kDegenerateTranslation) ++degenerate;
    d.max_error = std::max(d.max_error, std::fabs(error));
    d.end_error = error;
  }
  d.zone_start = start_x;
  d.zone_length = x - start_x;
  d.degenerate_fraction = zone_sweeps > 0 ? static_cast<double>(degenerate) / zone_sweeps : 0.0;
  return d;
}

TEST(SimFeatureless, DegeneracyPriorBoundsAxialDrift) {
  FeatureConfig fc;
  fc.preprocess.max_range = static_cast<float>(kRange);
  // 60 s: 2 s standing, ~28 m to the zone, then ~45 m inside it.
  const test::SimRun run = test::simulateRun("featureless", "vlp16", 60.0, 1, fc);
  const AxialDrift with = runPipeline(run, true), without = runPipeline(run, false);
  for (const auto& [name, d] : {std::pair{"prior", with}, std::pair{"no prior", without}})
    std::printf("featureless %s: zone from %.1f m, %.1f m driven in it, axial error max %.2f m end %+.2f m, "
                "mapping degenerate in %.0f%% of zone sweeps\n",
                name, d.zone_start, d.zone_length, d.max_error, d.end_error, 100.0 * d.degenerate_fraction);
  // Measured (seed 1): with the prior the axial error peaks at 6.4 m over 44.6 m in the zone (the velocity
  // held is 10-15% low: it was averaged while the axis was still barely observed, see limits in
  // lib/features/README.md); without it 71 m (the estimate slides and jumps along the axis). Seed 2:
  // 2.1 m against 55 m. Before the edge noise floor, the remapping and the averaged velocity the estimate
  // stalled: 43 m behind at the end with the prior, 52 m without.
  ASSERT_GT(with.zone_length, 40.0);
  EXPECT_GT(with.degenerate_fraction, 0.9);  // the zone really is degenerate for the mapper (measured 100%)
  EXPECT_LT(with.max_error, 0.2 * with.zone_length);
  EXPECT_GT(without.max_error, 5.0 * with.max_error);
}

}  // namespace
}  // namespace adit
