// LCM messages of a run into a RunModel: LIDAR_POINTS, ODOM_MAPPED, GROUND_TRUTH, POSE_GRAPH, LOOP_CLOSURE,
// MAP_UPDATE, STATUS_<NAME>. Every message is checked against its type's wire layout (msg/wire_check.hpp) and
// its values (msg/validate.hpp) before it touches the model: a malformed or unexpected message is counted
// and skipped, never a crash. Other channels (IMU, FEATURES, ...) are ignored and counted.
#pragma once

#include "view/run_model.hpp"

#include <cstddef>
#include <cstdint>
#include <map>
#include <string>

namespace adit::view {

// What one message changed (bits).
enum Change : unsigned {
  kNoChange = 0,
  kSweepChanged = 1u << 0,
  kSubmapsAdded = 1u << 1,
  kSubmapsMoved = 1u << 2,
  kOdometryChanged = 1u << 3,     // a pose appended (the robot moved)
  kKeyframesChanged = 1u << 4,    // the pose graph: the corrected trajectory and the loops' ends moved
  kGroundTruthChanged = 1u << 5,
  kLoopsChanged = 1u << 6,
  kStatusChanged = 1u << 7,
};

struct DecodeCounts {
  std::int64_t used = 0;
  std::int64_t malformed = 0;   // wrong type on a known channel, bad layout, non-finite or absurd values
  std::int64_t out_of_order = 0;  // a pose not newer than the previous one on its channel
  std::map<std::string, std::int64_t> ignored;  // channels not shown, by name
  std::string last_error;
};

class RunDecoder {
 public:
  unsigned apply(const std::string& channel, const std::uint8_t* data, std::size_t size, RunModel& model);
  const DecodeCounts& counts() const { return counts_; }

 private:
  unsigned sweep(const std::uint8_t* data, std::size_t size, RunModel& model);
  unsigned mapped(const std::uint8_t* data, std::size_t size, RunModel& model);
  unsigned groundTruth(const std::uint8_t* data, std::size_t size, RunModel& model);
  unsigned poseGraph(const std::uint8_t* data, std::size_t size, RunModel& model);
  unsigned loopClosure(const std::uint8_t* data, std::size_t size, RunModel& model);
  unsigned mapUpdate(const std::uint8_t* data, std::size_t size, RunModel& model);
  unsigned status(const std::uint8_t* data, std::size_t size, RunModel& model);
  unsigned refuse(const std::string& channel, const std::string& why);

  DecodeCounts counts_;
};

}  // namespace adit::view
