// Trajectory files: TUM text, KITTI 3x4 pose files, KITTI calib.txt, times.txt.
//
// Readers throw std::runtime_error("<path>:<line>: <what is wrong>") on a bad line or a missing file;
// they never crash on malformed input. Writers write to "<path>.tmp" and rename it over <path>, so a
// reader never sees a half-written file.
#pragma once

#include "core/types.hpp"

#include <string>
#include <vector>

namespace adit::eval {

enum class TrajectoryFormat { kTum, kKitti };

// TUM RGB-D format: one pose per line, "t x y z qx qy qz qw", t in seconds; '#' lines and blank lines skipped.
Trajectory readTum(const std::string& path);
void writeTum(const std::string& path, const Trajectory& trajectory);

// KITTI odometry pose file: one pose per line, 12 numbers = the top 3x4 of the 4x4 pose, row-major.
// Timestamps come from `times` (seconds, one per pose, e.g. read by readTimes) when it is non-empty,
// otherwise pose i gets t = i * frame_period_s (KITTI's lidar runs at 10 Hz).
Trajectory readKitti(const std::string& path, const std::vector<double>& times = {}, double frame_period_s = 0.1);
void writeKitti(const std::string& path, const Trajectory& trajectory);

// KITTI times.txt: one timestamp in seconds per line.
std::vector<double> readTimes(const std::string& path);

// Tr from a KITTI calib.txt ("Tr:" or "Tr_velo_to_cam:" line): velodyne -> left camera, as a 4x4 isometry.
Eigen::Isometry3d readKittiVeloToCam(const std::string& calib_path);

// KITTI ground truth is the left-camera pose P_i (camera i in camera-0 frame). The lidar-frame pose is
// T_velo_i = Tr^-1 * P_i * Tr, so the first lidar pose is the identity like the first camera pose.
Trajectory cameraToLidar(const Trajectory& camera_poses, const Eigen::Isometry3d& velo_to_cam);
Trajectory lidarToCamera(const Trajectory& lidar_poses, const Eigen::Isometry3d& velo_to_cam);

// Write any text file atomically (temp file + rename), e.g. a JSON report.
void writeTextFile(const std::string& path, const std::string& content);

// Guess the format from the first data line: 8 numbers -> TUM, 12 numbers -> KITTI. Throws if neither.
TrajectoryFormat detectFormat(const std::string& path);

// Parse "tum" / "kitti"; throws std::invalid_argument otherwise.
TrajectoryFormat parseFormat(const std::string& name);

}  // namespace adit::eval
