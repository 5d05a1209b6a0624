// The figures of `adit bench pipeline` as named numbers, written to and read from JSON, and the comparison
// of two runs (`adit bench compare a.json b.json`): one line per figure with its change, regressions flagged.
#pragma once

#include "pipeline/replay.hpp"

#include <string>
#include <vector>

namespace adit::pipeline {

struct BenchFigure {
  std::string name;  // "feature.cpu_median_ms", "wall_ms_per_sweep", ...
  double value = 0;
  std::string unit;
  bool higher_is_better = false;  // realtime_factor; every time and memory figure is better lower
};

std::vector<BenchFigure> benchFigures(const ReplayReport& report);
// CPU ms the threads working for a stage beside its own took in all (search threads, the feature stage's
// threads, the loop closer's worker: its STATUS counter helper_cpu_ms), or a negative number for a stage
// without such threads: a cost the stage's own-thread CPU does not show.
double helperCpuMs(const StageTiming& stage);
// {"input": ..., "figures": [{"name", "value", "unit", "higher_is_better"}, ...]}
std::string benchFiguresJson(const std::vector<BenchFigure>& figures, const std::string& input);
// Throws std::runtime_error naming the file when it cannot be read or is not such a JSON file.
std::vector<BenchFigure> readBenchFigures(const std::string& path);

struct FigureChange {
  std::string name, unit;
  double before = 0, after = 0;
  double change_pct = 0;    // (after - before) / before
  bool regression = false;  // worse by more than the tolerance
  bool missing = false;     // only in one of the two files
  double change_min_pct = 0, change_max_pct = 0;  // over the pairs (compareFigurePairs; one pair: change_pct)
  bool higher_is_better = false;                    // as BenchFigure's: which way is worse
};

std::vector<FigureChange> compareFigures(const std::vector<BenchFigure>& before, const std::vector<BenchFigure>& after,
                                         double tolerance_pct);

// Runs of two builds taken in turn (before, after, before, after ...), pair i = before[i] and after[i]: a
// machine whose speed drifts moves both runs of a pair alike, so each figure's change is the median of the
// pairs' changes (with their range), its before and after the medians of each side. A figure that any run
// lacks is reported missing. Throws std::invalid_argument unless both sides have the same number of runs (>= 1).
std::vector<FigureChange> compareFigurePairs(const std::vector<std::vector<BenchFigure>>& before,
                                             const std::vector<std::vector<BenchFigure>>& after, double tolerance_pct);

}  // namespace adit::pipeline
