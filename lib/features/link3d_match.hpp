// LinK3D descriptor matching and RANSAC rigid alignment of the matched keypoints.
#pragma once

#include "core/types.hpp"
#include "features/feature_config.hpp"

#include <vector>

namespace adit {

struct LinK3dMatch {
  int a = -1;     // keypoint index in set a
  int b = -1;     // keypoint index in set b
  int score = 0;  // agreeing bins
};

// Similarity: bins non-zero in both descriptors whose values differ by less than tolerance (m).
int linK3dScore(const LinK3dDescriptor& x, const LinK3dDescriptor& y, float tolerance);

// One-to-one matches: each keypoint of a takes its best-scoring keypoint of b (ties: lowest index); when
// several of a pick the same b only the best (ties: lowest a) keeps it; scores below cfg.min_score dropped.
// Sorted by a.
std::vector<LinK3dMatch> matchLinK3d(const std::vector<LinK3dDescriptor>& a, const std::vector<LinK3dDescriptor>& b,
                                     const LinK3dConfig& cfg);
std::vector<LinK3dMatch> matchLinK3d(const FeatureSet& a, const FeatureSet& b, const LinK3dConfig& cfg);

struct RansacResult {
  bool ok = false;                                         // enough inliers for a reliable transform
  Eigen::Isometry3d T_a_b = Eigen::Isometry3d::Identity();  // p_a = T_a_b * p_b
  std::vector<LinK3dMatch> inliers;
  double rms = 0.0;  // RMS residual of the inliers (m)
};

// Rigid transform from matched keypoints: 3-point hypotheses drawn by a seeded std::mt19937, the one with
// most inliers (ties: first found) refined by robustly weighted least squares on its inliers (see
// RansacConfig::robust_scale). Deterministic for given inputs and seed.
RansacResult estimateTransformRansac(const std::vector<Eigen::Vector3f>& keypoints_a,
                                     const std::vector<Eigen::Vector3f>& keypoints_b,
                                     const std::vector<LinK3dMatch>& matches, const RansacConfig& cfg);

namespace features {
// Weighted least-squares rigid transform (Kabsch, no scale) with p_a ~ T * p_b over the given pairs;
// empty weights = all 1. Identity if fewer than 3 pairs.
Eigen::Isometry3d fitRigid(const std::vector<Eigen::Vector3f>& keypoints_a, const std::vector<Eigen::Vector3f>& keypoints_b,
                           const std::vector<LinK3dMatch>& pairs, const std::vector<double>& weights = {});

}  // namespace features
}  // namespace adit
