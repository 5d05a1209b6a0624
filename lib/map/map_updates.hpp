// What a viewer needs to follow the corrected map without pulling it whole: the map is a list of submaps,
// one per keyframe (its decimated cloud in the keyframe's frame), each placed by its keyframe's corrected
// pose. A new keyframe is sent once with its points; when a loop correction moves keyframes, only their new
// poses are sent. Updates go out at most once per period of sensor time, each bounded in points, so the
// bandwidth is bounded whatever the pose graph does.
#pragma once

#include "core/config_table.hpp"
#include "loop/loop_closer.hpp"

#include <optional>
#include <vector>

namespace adit {

struct MapUpdateConfig {
  double period_s = 1.0;            // map.update_period_s: least sensor time between two updates
  double voxel_m = 0.4;             // map.update_voxel_m: decimation of a submap's points for viewers
  double move_threshold_m = 0.02;   // map.update_move_m: a submap moved less than this (and the angle) is not resent
  double move_threshold_deg = 0.2;  // map.update_move_deg
  int max_points = 40000;           // map.update_max_points: points per update; more new submaps wait
  int max_moved = 5000;             // map.update_max_moved: moved poses per update; more wait
};
// Keys "map.*" (MAP_UPDATE's rate and decimation), read through this table.
const ConfigTable<MapUpdateConfig>& mapUpdateConfigTable();
MapUpdateConfig mapUpdateConfigFrom(const Config& config);

struct SubmapPose {
  int id = 0;  // the keyframe's number in the order made (LoopCloser::Keyframe::seq)
  std::int64_t utime = 0;
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
};

struct NewSubmap {
  SubmapPose where;
  std::vector<Eigen::Vector3f> points;  // keyframe lidar frame
};

struct MapUpdate {
  std::int64_t utime = 0;
  int num_submaps = 0;
  int num_loops = 0;
  std::vector<NewSubmap> added;
  std::vector<SubmapPose> moved;
};

class MapUpdateTracker {
 public:
  explicit MapUpdateTracker(MapUpdateConfig config = {}) : config_(config) {}

  // After each sweep: the update due at sensor time `utime`, if one is due and anything changed.
  std::optional<MapUpdate> update(std::int64_t utime, const LoopCloser& closer);

 private:
  MapUpdateConfig config_;
  struct Sent {
    std::int64_t seq = 0;
    Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();  // as last sent
  };
  std::vector<Sent> sent_;  // by seq; a keyframe merged out of the graph is forgotten
  std::int64_t next_seq_ = 0;  // the first keyframe not sent yet
  std::int64_t last_utime_ = -1;
};

}  // namespace adit
