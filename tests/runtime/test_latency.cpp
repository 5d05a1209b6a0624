// The latency statistic on STATUS (runtime/latency.hpp): arrival and output matched by sensor time,
// quantiles of known samples, sweeps that never complete counted, the STATUS counters' names and units.
#include "runtime/latency.hpp"
#include "runtime/status.hpp"

#include <gtest/gtest.h>

namespace adit::runtime {
namespace {

TEST(Latency, QuantilesOfKnownLatencies) {
  LatencyTracker t;
  // Sweeps every 100 ms; sweep i completes after (i + 1) ms: latencies 1..100 ms.
  for (int i = 0; i < 100; ++i) {
    const std::int64_t utime = 1'000'000 + i * 100'000, arrival = 5'000'000'000 + i * 100'000;
    t.arrived(utime, arrival);
    EXPECT_TRUE(t.completed(utime, arrival + (i + 1) * 1000));
  }
  const LatencySummary s = t.summary();
  EXPECT_EQ(s.samples, 100);
  EXPECT_EQ(s.unmatched, 0);
  EXPECT_NEAR(s.p50_ms, 50.5, 0.51);
  EXPECT_NEAR(s.p95_ms, 95.0, 1.01);
  EXPECT_NEAR(s.p99_ms, 99.0, 1.01);
  EXPECT_DOUBLE_EQ(s.max_ms, 100.0);
}

TEST(Latency, MatchesBySensorTimeAndCountsSweepsThatNeverComplete) {
  LatencyTracker t;
  t.arrived(100, 1'000);
  t.arrived(200, 2'000);  // dropped by a stage: never completes
  t.arrived(300, 3'000);
  t.arrived(300, 9'000);  // a repeated arrival keeps the first stamp
  EXPECT_FALSE(t.completed(150, 4'000)) << "an output with no known arrival is no sample";
  EXPECT_TRUE(t.completed(100, 11'000));
  EXPECT_TRUE(t.completed(300, 23'000));
  EXPECT_FALSE(t.completed(300, 24'000)) << "each arrival completes once";
  const LatencySummary s = t.summary();
  EXPECT_EQ(s.samples, 2);
  EXPECT_EQ(s.unmatched, 1);
  EXPECT_DOUBLE_EQ(s.max_ms, 20.0);
  EXPECT_DOUBLE_EQ(t.summary().p50_ms, 20.0);  // lround of the middle index of {10, 20}
}

TEST(Latency, BoundedWindowAndPendingArrivals) {
  LatencyTracker t(/*window=*/10, /*pending=*/4);
  for (int i = 0; i < 10; ++i) t.arrived(i, 0);  // 6 forgotten: the output stage has fallen far behind
  EXPECT_EQ(t.summary().unmatched, 6);
  EXPECT_FALSE(t.completed(2, 1'000));
  EXPECT_TRUE(t.completed(6, 1'000));
  for (int i = 0; i < 50; ++i) {
    t.arrived(100 + i, 0);
    t.completed(100 + i, (i < 40 ? 500'000 : 1'000));  // the window keeps the newest 10 (1 ms each)
  }
  EXPECT_EQ(t.summary().samples, 10);
  EXPECT_DOUBLE_EQ(t.summary().max_ms, 1.0);
}

TEST(Latency, ReportedAsStatusCountersInMicroseconds) {
  LatencyTracker t;
  t.arrived(1, 0);
  t.completed(1, 12'345);
  adit::status_t status;
  status.num_counters = 1;
  status.counter_names = {"decode_error"};
  status.counter_values = {3};
  addLatencyCounters(status, "points_to_mapped", t.summary());
  ASSERT_EQ(status.num_counters, 7);
  ASSERT_EQ(status.counter_names.size(), 7u);
  ASSERT_EQ(status.counter_values.size(), 7u);
  const std::vector<std::string> names{"decode_error", "points_to_mapped_p50_us", "points_to_mapped_p95_us",
                                       "points_to_mapped_p99_us", "points_to_mapped_max_us",
                                       "points_to_mapped_samples", "points_to_mapped_unmatched"};
  EXPECT_EQ(status.counter_names, names);
  EXPECT_EQ(status.counter_values[1], 12'345);
  EXPECT_EQ(status.counter_values[4], 12'345);
  EXPECT_EQ(status.counter_values[5], 1);
  EXPECT_EQ(status.counter_values[6], 0);
}

}  // namespace
}  // namespace adit::runtime
