// A run's LCM messages as Foxglove channels, written to a sink (an MCAP file for adit export mcap, the Foxglove
// WebSocket protocol for adit view --foxglove):
//   /lidar/points            foxglove.PointCloud      LIDAR_POINTS, frame "lidar" (x, y, z, intensity)
//   /tf                      foxglove.FrameTransform  world -> lidar (ODOM_MAPPED, as corrected then),
//                                                     world -> ground_truth (GROUND_TRUTH)
//   /trajectory/odometry     foxglove.PosesInFrame    before loop correction (ODOM_MAPPED without its correction)
//   /trajectory/corrected    foxglove.PosesInFrame    after: each pose moved with its keyframe (POSE_GRAPH)
//   /trajectory/ground_truth foxglove.PosesInFrame    GROUND_TRUTH
//   /loops                   foxglove.SceneUpdate     one LINE_LIST entity: the accepted loops between keyframes
//   /map                     foxglove.PointCloud      the corrected map (MAP_UPDATE's submaps placed), frame "world"
//   /status/<process>        adit.Status              STATUS_<NAME> as JSON
// Trajectories and the map are whole each time they are written, so they are written at most once per
// period of log time (and the map at once when a loop moves it, and everything at the end).
#pragma once

#include "foxglove/foxglove_schemas.hpp"
#include "view/run_decoder.hpp"

#include <cstdint>
#include <map>
#include <string>

namespace adit::foxglove {

struct ExportOptions {
  int sweep_every = 1;               // every n-th sweep
  double map_period_s = 5.0;         // least log time between two /map clouds (a loop correction aside)
  double trajectory_period_s = 1.0;  // least log time between two trajectory messages
  double trajectory_step_m = 0.1;    // poses thinned to this spacing in the trajectory messages
};

// Where the messages go: one JSON message on a topic with its schema, at a log time in nanoseconds.
class FoxgloveSink {
 public:
  virtual ~FoxgloveSink() = default;
  virtual void publish(const std::string& topic, const SchemaText& schema, const std::string& json,
                       std::uint64_t log_ns) = 0;
};

class FoxgloveRun {
 public:
  FoxgloveRun(FoxgloveSink& sink, ExportOptions options);

  // One LCM event of the run, in log order; log_utime (µs) becomes the messages' log time.
  void add(const std::string& channel, const std::uint8_t* data, std::size_t size, std::int64_t log_utime);
  // The last trajectories and map (the end of a file).
  void finish();

  const view::DecodeCounts& decodeCounts() const { return decoder_.counts(); }
  // Messages written per topic.
  const std::map<std::string, std::uint64_t>& topics() const { return written_; }

 private:
  void publish(const std::string& topic, const std::string& schema, const std::string& json);
  void writeTrajectories(std::int64_t utime);
  void writeMap(std::int64_t utime);

  FoxgloveSink& sink_;
  ExportOptions options_;
  view::RunModel model_;
  view::RunDecoder decoder_;
  std::map<std::string, std::uint64_t> written_;
  std::int64_t log_utime_ = 0;
  std::int64_t sweeps_seen_ = 0;
  std::int64_t last_trajectory_utime_ = -1, last_map_utime_ = -1;
  bool trajectories_pending_ = false, map_pending_ = false;
};

}  // namespace adit::foxglove
