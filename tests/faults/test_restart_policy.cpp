// The launcher's restart arithmetic: back-off doubling to its cap, reset after a healthy run, giving up after
// too many exits within the window and not when they are spread out.
#include "launch/restart_policy.hpp"

#include <gtest/gtest.h>

using adit::launch::RestartLimits;
using adit::launch::RestartPolicy;

TEST(RestartPolicy, BacksOffDoublingToTheCap) {
  RestartPolicy p(RestartLimits{100, 1000.0, 1.0, 30.0, 30.0});
  double t = 0;
  std::vector<double> delays;
  for (int i = 0; i < 7; ++i) {
    const auto d = p.onExit(t, 0.1);
    ASSERT_TRUE(d);
    delays.push_back(*d);
    t += *d + 0.1;
  }
  EXPECT_EQ(delays, (std::vector<double>{1, 2, 4, 8, 16, 30, 30}));
}

TEST(RestartPolicy, HealthyRunResetsTheBackOff) {
  RestartPolicy p;
  EXPECT_EQ(*p.onExit(0, 0.5), 1.0);
  EXPECT_EQ(*p.onExit(2, 0.5), 2.0);
  EXPECT_EQ(*p.onExit(100, 60.0), 1.0);  // ran 60 s: healthy
}

TEST(RestartPolicy, GivesUpAfterTooManyExitsInTheWindow) {
  RestartPolicy p(RestartLimits{3, 60.0});
  EXPECT_TRUE(p.onExit(0, 0.1));
  EXPECT_TRUE(p.onExit(1.2, 0.1));
  EXPECT_TRUE(p.onExit(3.4, 0.1));
  EXPECT_FALSE(p.onExit(7.6, 0.1));  // the 4th exit within 60 s
  EXPECT_EQ(p.exitsInWindow(), 4);
}

TEST(RestartPolicy, ExitsSpreadBeyondTheWindowNeverGiveUp) {
  RestartPolicy p(RestartLimits{2, 10.0});
  for (int i = 0; i < 20; ++i) EXPECT_TRUE(p.onExit(11.0 * i, 5.0)) << "exit " << i;
}

TEST(RestartPolicy, ZeroRestartsGivesUpAtOnce) {
  RestartPolicy p(RestartLimits{0, 60.0});
  EXPECT_FALSE(p.onExit(0, 100.0));
}
