// The initial guess of scan-to-scan odometry, in the paper's order of preference: LinK3D keypoint matches
// (RANSAC) when enough agree, else the IMU's rotation over the interval with the constant-velocity
// translation, else nothing (the odometry then uses its constant-velocity model).
#pragma once

#include "core/types.hpp"
#include "features/feature_config.hpp"

#include <optional>
#include <vector>

namespace adit {

struct InitialGuessConfig {
  bool use_link3d = true;  // odometry.use_link3d_seed: false reproduces A-LOAM (motion model only)
  bool use_imu = true;     // odometry.use_imu_rotation: gyro rotation between sweeps when IMU covers it
  // The LinK3D transform must agree with the motion model to within these, or it is a bad match set
  // (roadways repeat: a keypoint pattern can match one support arch further on).
  double max_link3d_deviation_m = 1.0;
  double max_link3d_deviation_deg = 15.0;
  // With no motion model yet (start-up), a LinK3D seed is accepted up to this speed times the interval: the
  // vehicle may already move (odometry.startup_max_speed_mps; the odometry's start-up search then weighs the
  // seed against seeds along the forward axis, so a matched support arch one spacing off cannot win alone).
  double startup_max_speed_mps = 30.0;
  LinK3dConfig link3d;
  RansacConfig ransac;
  Eigen::Quaterniond R_lidar_imu = Eigen::Quaterniond::Identity();
  double max_imu_gap_s = 0.02;
};

// Keys "odometry.use_link3d_seed", "odometry.use_imu_rotation", "odometry.max_link3d_deviation_*"; the LinK3D,
// RANSAC and IMU mounting keys are the feature stage's (features.link3d.*, features.ransac.*, features.deskew.*).
const ConfigTable<InitialGuessConfig>& initialGuessConfigTable();
InitialGuessConfig initialGuessConfigFrom(const Config& c);

struct InitialGuess {
  std::optional<Eigen::Isometry3d> T_prev_curr;  // unset: let the odometry use its motion model
  int flags = 0;                                 // PoseEstimate::kSeededBy*
  int link3d_matches = 0;
  int link3d_inliers = 0;
};

// previous may be null (first sweep). motion_model: the odometry's constant-velocity prediction of
// T_prev_curr; motion_known: false when that is the identity of ignorance (no velocity yet), not a
// measured standstill. imu: samples around the interval (any order of coverage; checked inside).
InitialGuess initialGuess(const FeatureSet* previous, const FeatureSet& current, const Eigen::Isometry3d& motion_model,
                          bool motion_known, const std::vector<ImuSample>& imu, const InitialGuessConfig& config);

}  // namespace adit
