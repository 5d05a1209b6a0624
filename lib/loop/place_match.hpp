// The steps of a place match that loop closure and relocalisation on a saved map share: the Scan Context of a
// keyframe (in a levelled frame), the seed a Scan Context match gives ICP, and the verification of a candidate
// against its neighbourhood (each neighbour at its own pose). The decisions around them (odometry gate,
// consistency, ambiguity) stay with each user.
#pragma once

#include "loop/compact_cloud.hpp"
#include "loop/loop_verifier.hpp"
#include "loop/scan_context.hpp"

#include <Eigen/Geometry>

#include <memory>
#include <vector>

namespace adit {

// Rotation that removes the heading of a pose but keeps its roll and pitch: levelled = L * lidar.
Eigen::Matrix3d levellingRotation(const Eigen::Isometry3d& T_world_lidar);

// Scan Context of a keyframe's points (lidar frame) taken at T_world_lidar; levelled (roll and pitch removed)
// when `levelled`, so a sloping roadway or a tilted robot does not shift heights between visits.
ScanContext keyframeScanContext(std::vector<Eigen::Vector3f> points, const Eigen::Isometry3d& T_world_lidar,
                                bool levelled, const ScanContextConfig& config);

// Initial T_match_query from a Scan Context match: the yaw at zero offset (levelled frames: query =
// Rz(yaw) * match) with each keyframe's own roll and pitch.
Eigen::Isometry3d scanContextSeed(const Eigen::Isometry3d& T_world_query, const Eigen::Isometry3d& T_world_match,
                                  double yaw, bool levelled);

// A candidate's neighbourhood: keyframe clouds (lidar frame) and each one's pose relative to the candidate.
struct CandidateNeighbourhood {
  std::vector<CompactCloud> clouds;
  std::vector<Eigen::Isometry3d> T_match_cloud;
};

// The neighbourhood's submap (in the candidate's frame) as an ICP target.
std::unique_ptr<PlaneTarget> candidateTarget(const CandidateNeighbourhood& neighbourhood, const LoopVerifierConfig& config);

// ICP of the query keyframe's cloud against the neighbourhood's submap, from the seeds in order (verifyLoop).
LoopVerification verifyCandidate(const CompactCloud& query, const CandidateNeighbourhood& neighbourhood,
                                 const std::vector<Eigen::Isometry3d>& seeds, const LoopVerifierConfig& config);

}  // namespace adit
