// `adit replay`: runs every pipeline stage that exists, in lockstep in one process, over an input log, as
// fast as possible, and writes the run's products into one folder:
//   output.lcmlog  every message the pipeline published (deterministic: byte-identical run after run)
//   odometry.tum   poses before loop correction, one per sweep (when odometry/mapping exist)
//   trajectory.tum final poses, one per sweep (loop-corrected when the loop closer exists)
//   map.pcd        the map (when the mapper exists)
//   timing.json    per-stage ms median/p95/max and peak memory (the only product that varies run to run)
#pragma once

#include "core/config.hpp"

#include <cstdint>
#include <functional>
#include <map>
#include <string>
#include <vector>

namespace adit {
namespace runtime {
class MessageSource;
}
namespace pipeline {

struct ReplayOptions {
  std::string input_log;
  // Instead of a log: messages straight from a source (the simulator), no intermediate file.
  runtime::MessageSource* source = nullptr;
  std::string out_dir;
  Config config;
  std::vector<std::string> stages;  // empty: every stage that is written
  std::string record = ".*";        // regex of the channels written to output.lcmlog
  // Regex of odometry_t channels not matched by `record` written to output.lcmlog as the pose alone (points
  // stripped): the trajectory in a few hundred bytes a sweep. "" = none.
  std::string record_poses;
  // Relocalise in this map bundle (reloc.prior_map): adds the relocaliser stage after the others, which writes
  // map_trajectory.tum (poses in the bundle's frame, from the first fix on) and relocalisation.json.
  std::string prior_map;
  // Also write a map bundle (map/map_bundle.hpp) of the run into this folder ("" = none); needs the loop closer.
  std::string save_bundle;
  // Called now and then with the fraction of the input consumed (progress bars).
  std::function<void(double)> on_progress;
  // Run the feature stage and odometry of a sweep beside the mapper and loop closer of the sweep before, on
  // two threads (runtime/pipelined_bus.hpp): the same output byte for byte, faster. false: one thread.
  bool pipelined = true;
};

struct StageTiming {
  std::string stage;
  std::size_t calls = 0;
  double median_ms = 0, p95_ms = 0, max_ms = 0;  // wall time of the stage's main input (a sweep)
  double cpu_median_ms = 0, cpu_p95_ms = 0;       // CPU time of the same calls (the stage's thread)
  double wall_total_ms = 0, cpu_total_ms = 0;     // over every input of the stage
  std::map<std::string, std::int64_t> counters;   // the stage's STATUS counters at the end of the run
};

struct ReplayReport {
  std::vector<std::string> stages_run;
  std::int64_t input_events = 0;
  std::int64_t output_events = 0;
  std::int64_t corrupt_frames = 0;
  bool truncated = false;
  std::int64_t stage_errors = 0;  // errors + drops counted by the stages
  std::int64_t sweeps = 0;        // lidar sweeps in the input
  double sensor_seconds = 0;      // span of sensor time in the input
  double wall_seconds = 0;
  double peak_memory_mb = 0;
  double process_cpu_seconds = 0;  // user + system of every thread of this process (getrusage)
  std::vector<StageTiming> timing;
  std::vector<std::string> products;  // files written
};

// Throws std::runtime_error if the input cannot be read or the outputs cannot be written.
ReplayReport runReplay(const ReplayOptions& options);

// Peak resident memory of this process in MB (VmHWM), 0 if unknown.
double peakMemoryMb();
// User + system CPU seconds of this process, every thread.
double processCpuSeconds();

}  // namespace pipeline
}  // namespace adit
