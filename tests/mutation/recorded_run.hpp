// Real messages of every channel the pipeline's nodes receive: a short simulated run (roadway-loop, VLP-16)
// through all four nodes in lockstep, as `adit sim` + `adit replay --record-all` would log it, every message in
// the order the nodes received it. LIDAR_POINTS also in the full-float format of older logs, POSE_GRAPH and
// MAPPER_COMMAND made the way the loop closer and an operator send them (a short run closes no loop).
#pragma once

#include "core/config.hpp"

#include <cstdint>
#include <string>
#include <vector>

namespace adit::mutation {

struct Event {
  std::string channel;
  std::vector<std::uint8_t> bytes;
  std::int64_t utime = 0;
};

struct RecordedRun {
  std::vector<Event> events;  // bus order; LIDAR_POINTS compact
  std::vector<Event> full_sweeps;  // the same sweeps as point_cloud_t, one per compact LIDAR_POINTS event, in order
  // The run's own map bundle (its loop closer's, written at the end) in a temporary folder: the relocaliser's
  // reloc.prior_map, so that it relocalises in the very roadway the recorded messages drive through. The
  // caller removes it.
  std::string bundle_dir;
};

RecordedRun recordRun(const Config& config, double seconds, int seed);

}  // namespace adit::mutation
