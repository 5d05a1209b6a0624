// Plain data types shared by every stage. No LCM, no PCL, no I/O here: stages take and return these.
//
// Conventions (see README "Conventions"):
//  - Poses are T_world_lidar as Eigen::Isometry3d; units SI; angles in radians.
//  - Time is int64 microseconds (utime) of sensor time, never the wall clock.
//  - A sweep's utime is its reference instant = the time of its LAST firing. Each point's dt is its
//    firing time relative to that instant, so dt lies in [-sweep_duration, 0]. Deskewing moves every
//    point into the lidar frame at utime, and every pose of a sweep refers to that instant.
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>

#include <array>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

namespace adit {

struct LidarPoint {
  Eigen::Vector3f p = Eigen::Vector3f::Zero();  // metres, sensor frame
  float intensity = 0.0f;
  std::uint16_t ring = 0;  // beam index, 0 = lowest elevation
  float dt = 0.0f;         // seconds relative to the sweep's utime (<= 0)
};

struct LidarScan {
  std::int64_t utime = 0;      // reference instant: the sweep's last firing
  std::int64_t seq = 0;        // sequence number of the sweep in its stream
  std::string sensor;          // "vlp16", "rs16", "hdl64", ...
  int num_beams = 0;           // 0 if unknown
  float sweep_duration = 0.1f; // seconds
  bool has_ring = false;       // ring holds real beam indices
  bool has_time = false;       // dt holds real per-point times
  bool deskewed = false;       // points are compensated to utime
  bool partial = false;        // less than a revolution: the last one of a recording, published at its end
  std::vector<LidarPoint> points;
};

struct ImuSample {
  std::int64_t utime = 0;
  Eigen::Vector3d gyro = Eigen::Vector3d::Zero();   // rad/s, IMU frame
  Eigen::Vector3d accel = Eigen::Vector3d::Zero();  // m/s^2 specific force (+9.81 up at rest)
  std::optional<Eigen::Vector3d> magnetic_field;    // tesla
  std::optional<Eigen::Quaterniond> orientation;    // R_world_imu
};

// The accelerometer's specific force (+9.81 up at rest) over an interval, rotated into the lidar frame at
// its end and integrated once (a velocity change) and twice from rest at its start (a displacement): what a
// stage with better rotations than the gyro's needs to find gravity (mapping/gravity.hpp).
struct SpecificForceIntegral {
  std::int64_t since_utime = -1;  // start of the interval; -1: none (no IMU, samples that do not cover it)
  Eigen::Vector3d velocity_change = Eigen::Vector3d::Zero();  // m/s
  Eigen::Vector3d displacement = Eigen::Vector3d::Zero();     // m
  bool valid() const { return since_utime >= 0; }
};

struct StampedPose {
  std::int64_t utime = 0;
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();  // T_world_lidar
};

using Trajectory = std::vector<StampedPose>;

// LinK3D descriptor: 180 bins of 2 degrees around a keypoint, each the distance (m) to the nearest
// keypoint in that direction, 0 = empty.
constexpr int kLinK3dBins = 180;
using LinK3dDescriptor = std::array<float, kLinK3dBins>;

// Everything the feature stage extracts from one sweep (what odometry consumes).
struct FeatureSet {
  std::int64_t utime = 0;
  LidarScan cloud;  // preprocessed, deskewed sweep (lidar frame at utime), thinned when the extractor is asked to
  std::vector<LidarPoint> corner_sharp;
  std::vector<LidarPoint> corner_less_sharp;
  std::vector<LidarPoint> surf_flat;
  std::vector<LidarPoint> surf_less_flat;
  std::vector<Eigen::Vector3f> keypoints;     // LinK3D cluster centroids
  std::vector<LinK3dDescriptor> descriptors;  // one per keypoint

  // Flags (same bits as adit::features_t).
  static constexpr std::int32_t kEmptySweep = 1;
  static constexpr std::int32_t kFewKeypoints = 2;
  static constexpr std::int32_t kDeskewImu = 4;
  static constexpr std::int32_t kDeskewMotion = 8;
  static constexpr std::int32_t kEmptyRing = 16;
  std::int32_t flags = 0;

  // Preprocessing report.
  std::int32_t points_in = 0;
  std::int32_t removed_invalid = 0;
  std::int32_t removed_range = 0;
  std::int32_t removed_outlier = 0;
};

using Matrix6d = Eigen::Matrix<double, 6, 6>;

// A pose estimate for one sweep (what odometry and mapping produce).
struct PoseEstimate {
  std::int64_t utime = 0;
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();  // T_world_lidar
  Matrix6d covariance = Matrix6d::Identity();  // tangent order (tx ty tz rx ry rz), lidar frame
  Eigen::Vector3d translation_eigenvalues = Eigen::Vector3d::Zero();  // ascending
  Eigen::Vector3d rotation_eigenvalues = Eigen::Vector3d::Zero();     // ascending

  // Flags (same bits as adit::odometry_t).
  static constexpr std::int32_t kDegenerateTranslation = 1;
  static constexpr std::int32_t kDegenerateRotation = 2;
  static constexpr std::int32_t kSeededByLinK3d = 4;
  static constexpr std::int32_t kSeededByMotionModel = 8;
  static constexpr std::int32_t kSeededByImu = 16;
  static constexpr std::int32_t kRegistrationFailed = 32;
  static constexpr std::int32_t kLoopCorrected = 64;
  static constexpr std::int32_t kStandingStill = 512;  // the pose is held (odometry/standstill.hpp)
  std::int32_t flags = 0;
  int iterations = 0;
  double final_cost = 0.0;
  // ODOM_SCAN: the accelerometer since the previous sweep (odometry/specific_force.hpp).
  SpecificForceIntegral specific_force;
  // ODOM_MAPPED: gravity in the lidar frame (m/s^2, pointing down) as the accelerometer saw it with the robot's
  // own acceleration removed (mapping/gravity.hpp); zero where unknown (no IMU, the first seconds).
  Eigen::Vector3d gravity = Eigen::Vector3d::Zero();
};

// A verified loop closure between two keyframes.
struct LoopConstraint {
  int query_index = -1;
  int match_index = -1;
  std::int64_t query_utime = 0;
  std::int64_t match_utime = 0;
  Eigen::Isometry3d T_match_query = Eigen::Isometry3d::Identity();
  Matrix6d information = Matrix6d::Identity();  // tangent order (tx ty tz rx ry rz)
  double scan_context_distance = 0.0;
  double scan_context_yaw = 0.0;
  double fitness = 0.0;  // RMS point-to-plane residual after ICP (m)
  double inlier_ratio = 0.0;
};

inline double toSeconds(std::int64_t utime) { return static_cast<double>(utime) * 1e-6; }
inline std::int64_t toUtime(double seconds) { return static_cast<std::int64_t>(seconds * 1e6 + (seconds >= 0 ? 0.5 : -0.5)); }

}  // namespace adit
