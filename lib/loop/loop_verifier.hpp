// Geometric verification of a Scan Context candidate: align the query keyframe to a submap of the candidate's
// neighbourhood (each neighbour at its OWN pose) and accept only a tight fit that constrains all 6 directions.
#pragma once

#include "loop/point_to_plane_icp.hpp"

#include <vector>

namespace adit {

struct LoopVerifierConfig {
  IcpConfig icp;
  // Keyframes on each side of the candidate merged into the submap (with 1 m keyframes: +-5 m of roadway).
  int submap_neighbors = 5;
  // Voxel sizes (m) of the submap (target) and of the query cloud (source): the target is denser so that
  // normals are good, the source sparser so that ICP is fast.
  double submap_voxel = 0.25;
  double query_voxel = 0.5;
  // Fitness: RMS point-to-plane residual of the inliers (m) and the share of query points that are inliers.
  // A correct revisit in a rough-walled roadway fits to a few cm with most points; an aliased place fits worse.
  double max_rms = 0.06;
  double min_inlier_ratio = 0.6;
  // Smallest / largest eigenvalue of the fit's translation information (rotation marginalised out): below this
  // one direction (typically along a featureless straight roadway) is not constrained and the loop is rejected.
  double min_eigenvalue_ratio = 0.01;
  // Standard deviation (rad) of the least constrained rotation at the fit's residual: above it, rejected too.
  double max_rotation_sigma = 0.005;
};

enum class LoopVerdict {
  kAccepted,
  kTooFewPoints,
  kPoorFitness,
  kDegenerate,
};

struct LoopVerification {
  LoopVerdict verdict = LoopVerdict::kTooFewPoints;
  Eigen::Isometry3d T_match_query = Eigen::Isometry3d::Identity();
  IcpResult icp;
  int seed = -1;  // index of the seed that produced the result
};

// One neighbour of the candidate: its cloud (lidar frame) and its pose relative to the candidate keyframe.
struct SubmapPiece {
  const std::vector<Eigen::Vector3f>* cloud = nullptr;
  Eigen::Isometry3d T_match_keyframe = Eigen::Isometry3d::Identity();
};

// Submap in the candidate (match) keyframe's frame, voxel-downsampled.
std::vector<Eigen::Vector3f> buildSubmap(const std::vector<SubmapPiece>& pieces, double voxel);

// Tries the seeds (initial T_match_query) in order; the first that fits is checked for degeneracy.
LoopVerification verifyLoop(const std::vector<Eigen::Vector3f>& query_cloud,
                            const std::vector<Eigen::Vector3f>& submap,
                            const std::vector<Eigen::Isometry3d>& seeds, const LoopVerifierConfig& config);

// The same against a target built once (PlaneTarget(submap, config.icp)) and a source already downsampled
// (querySource), for a caller that aligns one query against one target from further seeds afterwards.
LoopVerification verifyLoopAgainst(const PlaneTarget& target, const std::vector<Eigen::Vector3f>& source,
                                   const std::vector<Eigen::Isometry3d>& seeds, const LoopVerifierConfig& config);
std::vector<Eigen::Vector3f> querySource(const std::vector<Eigen::Vector3f>& query_cloud, const LoopVerifierConfig& config);

// A tight fit (inlier RMS and ratio), converged or not.
bool fitsTightly(const IcpResult& result, const LoopVerifierConfig& config);
// The fit pins every direction (min_eigenvalue_ratio, max_rotation_sigma); else it is degenerate.
bool pinsEveryDirection(const FitObservability& fit, const LoopVerifierConfig& config);
// The fit pins two translations and every rotation: at most its weakest translation is free (the axis of a
// straight roadway, which a partial loop leaves to the odometry and the relocaliser searches along).
bool pinsAllButOneTranslation(const FitObservability& fit, const LoopVerifierConfig& config);

const char* toString(LoopVerdict verdict);

}  // namespace adit
