// What a watcher of a run needs to know, as plain C++ (no LCM): the corrected map as keyframe-anchored
// submaps (from MAP_UPDATE), the trajectory before loop correction (ODOM_MAPPED without its correction),
// the keyframes' corrected poses (POSE_GRAPH), the loops, the ground truth when simulated, the newest sweep
// and every process's last STATUS. Filled by RunDecoder; read by the MCAP export and by adit view.
#pragma once

#include <Eigen/Geometry>

#include <cstdint>
#include <map>
#include <string>
#include <utility>
#include <vector>

namespace adit::view {

struct TimedPose {
  std::int64_t utime = 0;
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
};

struct Submap {
  int id = 0;
  std::int64_t utime = 0;
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();  // corrected T_world_keyframe
  std::vector<Eigen::Vector3f> points;                     // keyframe frame
  std::uint32_t version = 0;                               // +1 each time its pose moves
};

struct Sweep {
  std::int64_t utime = 0;
  std::vector<Eigen::Vector3f> points;  // lidar frame at utime
  std::vector<float> intensity;         // 0..1 (sensor units scaled by the sweep's maximum)
};

struct StatusRow {
  std::string process, state, last_error;
  std::int64_t wall_utime = 0;  // STATUS stamps are wall-clock
  double uptime_s = 0;
  std::int64_t inputs = 0, outputs = 0, drops = 0, errors = 0;
  double proc_ms_p50 = 0, proc_ms_p95 = 0, proc_ms_max = 0, busy_fraction = 0, input_rate_hz = 0;
  std::vector<std::pair<std::string, std::int64_t>> counters;
};

struct Loop {
  std::int64_t query_utime = 0, match_utime = 0;
  bool operator==(const Loop& o) const { return query_utime == o.query_utime && match_utime == o.match_utime; }
};

struct RunModel {
  std::map<int, Submap> submaps;
  int map_loops = 0;                        // loops in the pose graph as MAP_UPDATE last said
  std::vector<TimedPose> odometry;          // ODOM_MAPPED poses without loop correction, in time order
  std::map<std::int64_t, Eigen::Isometry3d> keyframes;  // POSE_GRAPH: corrected keyframe poses by utime
  std::vector<TimedPose> ground_truth;
  std::vector<Loop> loops;
  std::map<std::string, StatusRow> status;  // by process name
  std::string newest_status;                // the process whose STATUS came last
  Sweep sweep;
  TimedPose robot;                          // newest ODOM_MAPPED pose (loop-corrected as published)
  bool has_robot = false;

  // Every odometry pose moved by the correction of the newest keyframe at or before it (keyframe
  // corrected pose times its uncorrected pose inverse); before the first keyframe: unchanged.
  std::vector<TimedPose> correctedTrajectory() const;
  // The loops as pairs of corrected keyframe positions (loops whose keyframes are not known are left out).
  std::vector<std::pair<Eigen::Vector3d, Eigen::Vector3d>> loopSegments() const;
  // The ground truth placed in the odometry's frame: moved so that its pose at the first odometry sweep
  // coincides with that sweep's pose (the simulator's world and the odometry's start differ); unmoved
  // while there is no common sweep.
  std::vector<TimedPose> groundTruthInWorld() const;
  Eigen::Isometry3d groundTruthAlignment() const;  // the move itself (identity while unknown)
  // Metres travelled along the odometry.
  double distance() const;
  // Every submap's points placed by its corrected pose.
  std::vector<Eigen::Vector3f> mapPoints() const;
  std::size_t mapPointCount() const;
};

// Poses at least `min_step_m` apart (the first and the last always kept): trajectories for display.
std::vector<TimedPose> thinTrajectory(const std::vector<TimedPose>& poses, double min_step_m);

}  // namespace adit::view
