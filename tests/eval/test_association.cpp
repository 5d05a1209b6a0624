// Timestamp association like evo's sync.associate_trajectories (t_max_diff 0.01 s by default).
#include "eval/association.hpp"
#include "fixtures.hpp"

#include <gtest/gtest.h>

namespace adit::eval {
namespace {

Trajectory stamps(const std::vector<double>& seconds) {
  Trajectory out;
  for (double s : seconds) out.push_back({toUtime(s), test::poseAt(Eigen::Vector3d(s, 0, 0), 0.0)});
  return out;
}

TEST(Associate, MissingAndExtraStampsDropOut) {
  std::vector<double> gt_s, est_s;
  for (int k = 0; k <= 100; ++k) gt_s.push_back(0.1 * k);  // 0..10 s at 10 Hz
  for (int k = 0; k <= 100; ++k)
    if (k % 3 != 0) est_s.push_back(0.1 * k + 0.003);        // every 3rd missing, 3 ms late
  est_s.push_back(20.0);                                      // extra, far outside the ground truth
  est_s.insert(est_s.begin(), -5.0);
  const AssociatedTrajectories a = associate(stamps(gt_s), stamps(est_s));
  EXPECT_EQ(a.gt_input, 101u);
  EXPECT_EQ(a.est_input, 69u);
  ASSERT_EQ(a.gt.size(), 67u);  // 101 - 34 multiples of 3
  for (std::size_t i = 0; i < a.gt.size(); ++i) {
    EXPECT_EQ(a.est[i].utime - a.gt[i].utime, 3000);
    EXPECT_NE(std::llround(toSeconds(a.gt[i].utime) * 10) % 3, 0);
  }
}

TEST(Associate, RespectsMaxDifference) {
  const Trajectory gt = stamps({1.0, 2.0, 3.0});
  const Trajectory est = stamps({1.0101, 2.0099, 3.02});
  EXPECT_EQ(associate(gt, est).gt.size(), 1u);          // only 2.0099 within 10 ms
  EXPECT_EQ(associate(gt, est, 25000).gt.size(), 3u);  // 25 ms
  EXPECT_EQ(associate(gt, est, 0).gt.size(), 0u);
}

TEST(Associate, ShorterTrajectoryDrivesTheSearch) {
  // Estimate at 100 Hz, ground truth at 10 Hz: each ground-truth pose takes its closest estimate.
  std::vector<double> gt_s, est_s;
  for (int k = 0; k < 10; ++k) gt_s.push_back(0.1 * k + 0.004);
  for (int k = 0; k < 100; ++k) est_s.push_back(0.01 * k);
  const AssociatedTrajectories a = associate(stamps(gt_s), stamps(est_s));
  ASSERT_EQ(a.gt.size(), 10u);
  for (std::size_t i = 0; i < 10; ++i) EXPECT_EQ(a.gt[i].utime - a.est[i].utime, 4000);

  // Unsorted input gives the same pairs (linear search fallback).
  Trajectory shuffled = stamps(est_s);
  std::reverse(shuffled.begin(), shuffled.end());
  const AssociatedTrajectories b = associate(stamps(gt_s), shuffled);
  ASSERT_EQ(b.gt.size(), 10u);
  for (std::size_t i = 0; i < 10; ++i) EXPECT_EQ(b.est[i].utime, a.est[i].utime);
}

TEST(Associate, TiesTakeTheEarlierStampAndEmptyInputsGiveNothing) {
  const AssociatedTrajectories a = associate(stamps({0.0, 0.010, 0.020}), stamps({0.015}), 10000);
  ASSERT_EQ(a.gt.size(), 1u);
  EXPECT_EQ(a.gt[0].utime, 10000);  // 5 ms either side: numpy argmin picks the first
  EXPECT_TRUE(associate({}, stamps({1.0})).gt.empty());
  EXPECT_TRUE(associate(stamps({1.0}), {}).gt.empty());
}

}  // namespace
}  // namespace adit::eval
