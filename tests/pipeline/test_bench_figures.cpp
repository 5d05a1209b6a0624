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
