// Loop-closure precision and recall against the ground truth (eval/loop_recall.hpp): revisits counted once
// per pass through a mapped place, closed only by a correct loop inside that pass.
#include "eval/loop_recall.hpp"

#include <gtest/gtest.h>

#include <cmath>

namespace {

using adit::eval::JudgedLoop;

// A circle of 20 m radius (126 m round) driven at 1 m/s for `seconds`, poses at 10 Hz.
adit::Trajectory circle(double seconds) {
  adit::Trajectory t;
  for (int i = 0; i <= static_cast<int>(seconds * 10); ++i) {
    const double s = i * 0.1, a = s / 20.0;
    adit::StampedPose p;
    p.utime = static_cast<std::int64_t>(std::llround(s * 1e6));
    p.pose.translation() = Eigen::Vector3d(20.0 * std::cos(a), 20.0 * std::sin(a), 0.0);
    t.push_back(p);
  }
  return t;
}

constexpr std::int64_t kSecond = 1'000'000;

TEST(LoopRecall, TheSecondLapIsOneRevisitClosedOnlyByACorrectLoopInIt) {
  const adit::Trajectory truth = circle(200.0);  // 1.6 laps: the second lap's first 74 m revisit the first
  const auto none = adit::eval::loopRecall(truth, {});
  EXPECT_EQ(none.revisits, 1);
  EXPECT_EQ(none.revisits_closed, 0);
  EXPECT_DOUBLE_EQ(none.recall(), 0.0);

  const auto first_lap = adit::eval::loopRecall(truth, {{60 * kSecond, true}});  // nothing to revisit yet
  EXPECT_EQ(first_lap.revisits_closed, 0);
  EXPECT_EQ(first_lap.correct, 1);

  const auto wrong = adit::eval::loopRecall(truth, {{150 * kSecond, false}});
  EXPECT_EQ(wrong.revisits_closed, 0);
  EXPECT_EQ(wrong.wrong, 1);
  EXPECT_DOUBLE_EQ(wrong.precision(), 0.0);

  const auto closed = adit::eval::loopRecall(truth, {{150 * kSecond, true}, {151 * kSecond, true}, {170 * kSecond, false}});
  EXPECT_EQ(closed.revisits, 1);
  EXPECT_EQ(closed.revisits_closed, 1);
  EXPECT_DOUBLE_EQ(closed.recall(), 1.0);
  EXPECT_NEAR(closed.precision(), 2.0 / 3.0, 1e-12);
}

TEST(LoopRecall, ANearbyPlaceTooRecentIsNoRevisit) {
  // Out 40 m along x and back: the way back passes within 3 m of the way out, but less than 50 m of
  // driving (the loop closer's own exclusion) separates the closest pairs near the turn, and the far end
  // of the way back is 80 m of driving from where it started.
  adit::Trajectory truth;
  for (int i = 0; i <= 800; ++i) {
    const double s = i * 0.1;
    adit::StampedPose p;
    p.utime = static_cast<std::int64_t>(std::llround(s * 1e6));
    p.pose.translation() = Eigen::Vector3d(s <= 40.0 ? s : 80.0 - s, s <= 40.0 ? 0.0 : 2.0, 0.0);
    truth.push_back(p);
  }
  adit::eval::LoopRecallConfig config;
  const auto r = adit::eval::loopRecall(truth, {}, config);
  EXPECT_EQ(r.revisits, 1);  // from where 50 m of driving lie between: the last 15 m of the way back
  config.min_travel_m = 100.0;
  EXPECT_EQ(adit::eval::loopRecall(truth, {}, config).revisits, 0);
  EXPECT_DOUBLE_EQ(adit::eval::loopRecall(truth, {}, config).recall(), 1.0);  // nothing to close
}

}  // namespace
