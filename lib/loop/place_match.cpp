#include "loop/place_match.hpp"

#include <cmath>

namespace adit {

Eigen::Matrix3d levellingRotation(const Eigen::Isometry3d& T_world_lidar) {
  const Eigen::Matrix3d R = T_world_lidar.linear();
  const double yaw = std::atan2(R(1, 0), R(0, 0));
  return Eigen::AngleAxisd(-yaw, Eigen::Vector3d::UnitZ()).toRotationMatrix() * R;
}

ScanContext keyframeScanContext(std::vector<Eigen::Vector3f> points, const Eigen::Isometry3d& T_world_lidar,
                                bool levelled, const ScanContextConfig& config) {
  if (levelled) {
    const Eigen::Matrix3f L = levellingRotation(T_world_lidar).cast<float>();
    for (Eigen::Vector3f& p : points) p = L * p;
  }
  return ScanContext::build(points, config);
}

Eigen::Isometry3d scanContextSeed(const Eigen::Isometry3d& T_world_query, const Eigen::Isometry3d& T_world_match,
                                  double yaw, bool levelled) {
  Eigen::Matrix3d L_q = Eigen::Matrix3d::Identity(), L_m = Eigen::Matrix3d::Identity();
  if (levelled) {
    L_q = levellingRotation(T_world_query);
    L_m = levellingRotation(T_world_match);
  }
  const Eigen::Matrix3d R_yaw = Eigen::AngleAxisd(-yaw, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = L_m.transpose() * R_yaw * L_q;
  return T;
}

std::unique_ptr<PlaneTarget> candidateTarget(const CandidateNeighbourhood& neighbourhood, const LoopVerifierConfig& config) {
  std::vector<std::vector<Eigen::Vector3f>> clouds;
  clouds.reserve(neighbourhood.clouds.size());
  for (const CompactCloud& cloud : neighbourhood.clouds) clouds.push_back(cloud.decode());
  std::vector<SubmapPiece> pieces;
  for (std::size_t i = 0; i < clouds.size() && i < neighbourhood.T_match_cloud.size(); ++i)
    pieces.push_back({&clouds[i], neighbourhood.T_match_cloud[i]});
  return std::make_unique<PlaneTarget>(buildSubmap(pieces, config.submap_voxel), config.icp);
}

LoopVerification verifyCandidate(const CompactCloud& query, const CandidateNeighbourhood& neighbourhood,
                                 const std::vector<Eigen::Isometry3d>& seeds, const LoopVerifierConfig& config) {
  return verifyLoopAgainst(*candidateTarget(neighbourhood, config), querySource(query.decode(), config), seeds, config);
}

}  // namespace adit
