// LinK3D keypoints and descriptors (Cui et al. 2022, "LinK3D: Linear Keypoints Representation for 3D LiDAR
// Point Cloud"), written from the paper: edge points -> 120 horizontal sectors -> clusters -> keypoints at
// cluster centroids -> 180-bin descriptors.
#pragma once

#include "core/types.hpp"
#include "features/feature_config.hpp"
#include "features/ring_cloud.hpp"
#include "features/smoothness.hpp"

#include <vector>

namespace adit::features {

// A cluster of edge points that became a keypoint.
struct LinK3dCluster {
  Eigen::Vector3f centroid = Eigen::Vector3f::Zero();
  int points = 0;
  int rings = 0;  // distinct rings among its points
};

// Edge points: usable points with smoothness above cfg.edge_threshold, offset above cfg.edge_min_offset,
// within cfg.max_range (horizontal).
// Stable keypoints need vertical structure: a merged cluster becomes a keypoint only with at least
// min_cluster_points points over min_cluster_rings rings. Output order: by sector of the cluster's first part.
std::vector<LinK3dCluster> extractLinK3dClusters(const RingCloud& cloud, const PointScores& scores,
                                                 const LinK3dConfig& cfg);

// Descriptor of every keypoint (paper eq. 3-4). Around keypoint i, the horizontal plane is split into 180
// bins of 2 deg, bin 0 centred on the direction to i's nearest keypoint; each bin holds the distance (m) to the
// nearest keypoint in that direction. Bins left empty are then filled from the same construction oriented
// on the 2nd and then the 3rd nearest keypoint (priority order), which makes the descriptor survive a
// nearest neighbour that is missing in the other sweep. Invariant to yaw and translation.
std::vector<LinK3dDescriptor> computeLinK3dDescriptors(const std::vector<Eigen::Vector3f>& keypoints);

}  // namespace adit::features
