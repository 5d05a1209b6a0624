// What a live run's processes last said on STATUS, read back from its recording: for `adit bench pipeline
// --live`, which runs the real processes and reports the mapper's LIDAR_POINTS -> ODOM_MAPPED latency.
#pragma once

#include "pipeline/bench_figures.hpp"

#include <adit/status_t.hpp>

#include <map>
#include <string>
#include <vector>

namespace adit::pipeline {

// The newest STATUS_* message of each process in an LCM log, by process name. Throws std::runtime_error if
// the log cannot be read.
std::map<std::string, adit::status_t> lastStatusByProcess(const std::string& log_path);

// A named counter of a STATUS message, or `fallback` if it has none.
std::int64_t statusCounter(const adit::status_t& status, const std::string& name, std::int64_t fallback = -1);

// Figures of a live run: latency "<name>.latency_p50_ms" ... "_max_ms" of the mapper's points_to_mapped
// probe, its sample count, and per process the processing p50 / p95 (ms) and inputs of its last STATUS.
std::vector<BenchFigure> liveFigures(const std::map<std::string, adit::status_t>& last_status);

}  // namespace adit::pipeline
