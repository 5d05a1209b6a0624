// Human-readable and JSON renderings of evaluation results, shared by `adit eval`, the demo report
// and `adit bench ablation`.
#pragma once

#include "eval/evaluate.hpp"

#include <optional>
#include <string>
#include <vector>

namespace adit::eval {

// Multi-line report: poses matched, alignment, APE stats, RPE per delta, KITTI drift (or why not),
// end-point error, distance. Numbers in metres / degrees with units in the text.
std::string formatReport(const EvalResult& result);

// All numbers of the result as one JSON object (deterministic key order; NaN/inf as null).
std::string toJson(const EvalResult& result);

// One row of an ablation table (the paper's Table 1/2: variant | max | min | mean | rmse | std).
struct ApeTableRow {
  std::string variant;
  ErrorStats ape_m;
  std::optional<double> ms_per_sweep;  // printed as an extra column when any row has it
};
// Fixed-width text table, APE translation in metres with 3 decimals, optional title line above.
std::string formatApeTable(const std::vector<ApeTableRow>& rows, const std::string& title = "");

}  // namespace adit::eval
