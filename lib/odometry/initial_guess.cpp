#include "odometry/initial_guess.hpp"

#include "core/geometry.hpp"
#include "features/deskew.hpp"
#include "features/link3d_match.hpp"
#include "odometry/scan_to_scan.hpp"

#include <cmath>

namespace adit {

const ConfigTable<InitialGuessConfig>& initialGuessConfigTable() {
  using G = InitialGuessConfig;
  static const ConfigTable<G> table = [] {
    ConfigTable<G> t("odometry");
    t.add("use_link3d_seed", &G::use_link3d, anyValue(), "", "seed from LinK3D matches (false: motion model only, A-LOAM)")
     .add("use_imu_rotation", &G::use_imu, anyValue(), "", "gyro rotation between sweeps as the seed's rotation when the IMU covers it")
     .add("max_link3d_deviation_m", &G::max_link3d_deviation_m, above(0), "m", "a LinK3D seed farther from the motion model is a bad match set")
     .add("max_link3d_deviation_deg", &G::max_link3d_deviation_deg, aboveUpTo(0, 180), "deg", "same for rotation")
     .add("startup_max_speed_mps", &G::startup_max_speed_mps, atLeast(0), "m/s", "fastest a vehicle may already move when odometry starts (start-up search range; 0 = no search)");
    return t;
  }();
  return table;
}

InitialGuessConfig initialGuessConfigFrom(const Config& c) {
  InitialGuessConfig g;
  // Plain A-LOAM (the ablation baseline) seeds from its motion model only.
  if (ablationConfigTable().read(c).aloam) g.use_link3d = g.use_imu = false;
  g = initialGuessConfigTable().read(c, g);
  const FeatureConfig features = featureConfigFrom(c);
  g.link3d = features.link3d;
  g.ransac = features.ransac;
  g.R_lidar_imu = features.deskew.R_lidar_imu;
  g.max_imu_gap_s = features.deskew.max_imu_gap_s;
  return g;
}

InitialGuess initialGuess(const FeatureSet* previous, const FeatureSet& current, const Eigen::Isometry3d& motion_model,
                          bool motion_known, const std::vector<ImuSample>& imu, const InitialGuessConfig& config) {
  InitialGuess guess;
  if (!previous) return guess;
  const double interval = toSeconds(current.utime - previous->utime);
  // Without a motion model the seed is judged by how far a vehicle can go in the interval.
  const double max_deviation_m =
      motion_known ? config.max_link3d_deviation_m
                   : std::max(config.max_link3d_deviation_m, config.startup_max_speed_mps * interval);
  if (config.use_link3d && !previous->keypoints.empty() && !current.keypoints.empty()) {
    const auto matches = matchLinK3d(*previous, current, config.link3d);
    guess.link3d_matches = static_cast<int>(matches.size());
    // p_prev = T_a_b * p_curr with a = previous, b = current: T_a_b is T_prev_curr.
    const RansacResult r = estimateTransformRansac(previous->keypoints, current.keypoints, matches, config.ransac);
    guess.link3d_inliers = static_cast<int>(r.inliers.size());
    const Eigen::Isometry3d deviation = motion_model.inverse() * r.T_a_b;
    if (r.ok && translationNorm(deviation) <= max_deviation_m &&
        rotationAngle(deviation) <= config.max_link3d_deviation_deg * M_PI / 180.0) {
      guess.T_prev_curr = r.T_a_b;
      guess.flags = PoseEstimate::kSeededByLinK3d;
      return guess;
    }
  }
  if (config.use_imu && !imu.empty()) {
    const auto rotations = features::imuRotations(imu, current.utime, {-interval}, config.R_lidar_imu, config.max_imu_gap_s);
    if (!rotations.empty()) {
      // rotations[0]: the lidar at the previous sweep in the current frame, i.e. R_curr_prev.
      Eigen::Isometry3d T = motion_model;
      T.linear() = rotations.front().conjugate().toRotationMatrix();
      guess.T_prev_curr = T;
      guess.flags = PoseEstimate::kSeededByImu;
    }
  }
  return guess;
}

}  // namespace adit
