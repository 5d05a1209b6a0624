// adit bench's figures: JSON round trip, and the comparison that flags a regression (a time or memory figure
// that grew, the real-time factor that fell) beyond the tolerance and nothing within it.
#include "pipeline/bench_figures.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <fstream>

using namespace adit::pipeline;

namespace {

ReplayReport report(double feature_cpu_ms, double wall_s) {
  ReplayReport r;
  r.sweeps = 100;
  r.sensor_seconds = 10;
  r.wall_seconds = wall_s;
  r.process_cpu_seconds = 2.0;
  r.peak_memory_mb = 60;
  StageTiming t;
  t.stage = "feature";
  t.median_ms = 5;
  t.cpu_median_ms = feature_cpu_ms;
  t.cpu_total_ms = feature_cpu_ms * 100;
  r.timing.push_back(t);
  return r;
}

const FigureChange& change(const std::vector<FigureChange>& changes, const std::string& name) {
  for (const FigureChange& c : changes)
    if (c.name == name) return c;
  throw std::runtime_error("no figure " + name);
}

}  // namespace

TEST(BenchFigures, JsonRoundTripsAndCompareFlagsOnlyRegressions) {
  const std::filesystem::path path = std::filesystem::temp_directory_path() / "adit_bench_figures_test.json";
  std::ofstream(path) << benchFiguresJson(benchFigures(report(4.0, 1.0)), "a \"quoted\" input");
  const auto before = readBenchFigures(path.string());
  std::filesystem::remove(path);
  ASSERT_EQ(before.size(), benchFigures(report(4.0, 1.0)).size());
  EXPECT_DOUBLE_EQ(change(compareFigures(before, before, 10), "feature.cpu_median_ms").before, 4.0);

  // CPU +25 %, wall twice as long (real-time factor halved): both regressions; memory unchanged: not one.
  const auto changes = compareFigures(before, benchFigures(report(5.0, 2.0)), 10);
  EXPECT_NEAR(change(changes, "feature.cpu_median_ms").change_pct, 25.0, 1e-9);
  EXPECT_TRUE(change(changes, "feature.cpu_median_ms").regression);
  EXPECT_TRUE(change(changes, "realtime_factor").regression);
  EXPECT_NEAR(change(changes, "realtime_factor").change_pct, -50.0, 1e-9);
  EXPECT_FALSE(change(changes, "peak_memory_mb").regression);
  // Faster is never a regression; within the tolerance neither.
  EXPECT_FALSE(change(compareFigures(before, benchFigures(report(3.0, 0.5)), 10), "feature.cpu_median_ms").regression);
  EXPECT_FALSE(change(compareFigures(before, benchFigures(report(4.3, 1.0)), 10), "feature.cpu_median_ms").regression);
}

// A stage's other threads (search threads, the loop closer's worker) are a cost its own-thread CPU does not
// show: a figure of their own, per sweep, only for a stage that reports them.
TEST(BenchFigures, HelperThreadsCpuIsAFigureOfItsOwn) {
  ReplayReport r = report(4.0, 1.0);
  StageTiming loop;
  loop.stage = "loop_closer";
  loop.counters["helper_cpu_ms"] = 250;
  r.timing.push_back(loop);
  const auto figures = benchFigures(r);
  const auto named = [&](const std::string& name) {
    return std::count_if(figures.begin(), figures.end(), [&](const BenchFigure& f) { return f.name == name; });
  };
  ASSERT_EQ(named("loop_closer.helper_cpu_ms_per_sweep"), 1);
  EXPECT_EQ(named("feature.helper_cpu_ms_per_sweep"), 0);
  const auto changes = compareFigures(figures, figures, 10);
  EXPECT_DOUBLE_EQ(change(changes, "loop_closer.helper_cpu_ms_per_sweep").before, 2.5);  // 250 ms over 100 sweeps
}

TEST(BenchFigures, ANonBenchmarkFileIsAClearError) {
  const std::filesystem::path path = std::filesystem::temp_directory_path() / "adit_bench_not_figures.json";
  std::ofstream(path) << "{\"stages\": {}}";
  try {
    readBenchFigures(path.string());
    FAIL() << "accepted a file without figures";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find(path.string()), std::string::npos);
  }
  std::filesystem::remove(path);
}

// Runs of two builds taken in turn on a machine whose speed drifts: each pair moves together, so the median of
// the pairs' changes shows the builds' 10 % difference where the medians of each side alone (the machine
// 1.0x, 1.6x, 1.2x slower over the three pairs) would mix drift into it; the range shows the spread.
TEST(BenchFigures, PairedRunsJudgeTheMedianOfThePairsChanges) {
  std::vector<std::vector<BenchFigure>> before, after;
  for (const double machine : {1.0, 1.6, 1.2}) {
    before.push_back(benchFigures(report(4.0 * machine, 1.0 * machine)));
    after.push_back(benchFigures(report(4.4 * machine, 1.1 * machine)));
  }
  after[1] = benchFigures(report(4.0 * 1.6 * 1.3, 1.1 * 1.6));  // one noisy pair: +30 % CPU
  const auto changes = compareFigurePairs(before, after, 20);
  const FigureChange& cpu = change(changes, "feature.cpu_median_ms");
  EXPECT_NEAR(cpu.change_pct, 10.0, 1e-9);  // median of +10, +30, +10
  EXPECT_NEAR(cpu.change_min_pct, 10.0, 1e-9);
  EXPECT_NEAR(cpu.change_max_pct, 30.0, 1e-9);
  EXPECT_NEAR(cpu.before, 4.0 * 1.2, 1e-9);  // each side's median
  EXPECT_FALSE(cpu.regression);              // 10 % within the 20 % tolerance, whatever one pair said
  EXPECT_TRUE(change(compareFigurePairs(before, after, 5), "feature.cpu_median_ms").regression);
  // The real-time factor is better higher: its median fall of ~9 % is judged as a fall.
  const FigureChange& rt = change(compareFigurePairs(before, after, 5), "realtime_factor");
  EXPECT_LT(rt.change_pct, -8.0);
  EXPECT_TRUE(rt.regression);
  // One pair is compareFigures itself; unequal sides are refused.
  EXPECT_NEAR(change(compareFigurePairs({before[0]}, {after[0]}, 20), "feature.cpu_median_ms").change_pct,
              change(compareFigures(before[0], after[0], 20), "feature.cpu_median_ms").change_pct, 1e-12);
  EXPECT_THROW(compareFigurePairs(before, {after[0]}, 20), std::invalid_argument);
  // A figure only a later run has is listed, as missing.
  after[2].push_back({"only_later", 1.0, "ms", false});
  EXPECT_TRUE(change(compareFigurePairs(before, after, 20), "only_later").missing);
  EXPECT_THROW(compareFigurePairs({}, {}, 20), std::invalid_argument);
}
