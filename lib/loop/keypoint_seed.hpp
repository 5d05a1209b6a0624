// The LinK3D seed of a loop candidate (Cui et al. 2022, used as the paper uses it for loop closure): the query
// keyframe's keypoint descriptors matched against each keyframe of the candidate's neighbourhood, the matched
// keypoints placed in the candidate's frame, and a rigid transform from them by RANSAC. Unlike the Scan Context
// seed (a yaw with no translation) it carries the whole offset between the two visits, so ICP can start near a
// revisit that passes metres to the side; and it is a second opinion on where the query lies in the submap.
#pragma once

#include "loop/keyframe_keypoints.hpp"

#include <Eigen/Geometry>

#include <vector>

namespace adit {

struct KeypointSeedConfig {
  bool use = true;             // loop.keypoints.use: seed and check verification with LinK3D keypoints
  float bin_tolerance = 0.2f;  // m: two descriptor bins agree when both are set and this close (as features.link3d)
  int min_score = 3;           // agreeing bins a match needs
  float inlier_threshold = 0.5f;  // m: a matched pair is an inlier when the transform brings it this close
  int min_inliers = 5;         // distinct query keypoints among the inliers for a seed
  int ransac_iterations = 200;
  // A seed agrees with a fit when they differ by less than this (the loop verifier's coarse ICP gate is 1.5 m).
  double agree_translation = 1.0;  // m
  double agree_rotation_deg = 5.0;
};

struct KeypointSeed {
  bool ok = false;
  Eigen::Isometry3d T_match_query = Eigen::Isometry3d::Identity();
  int matches = 0;  // descriptor matches over the whole neighbourhood
  int inliers = 0;  // distinct query keypoints that agree with T_match_query
};

// neighbours[i]'s keypoints (null: none) lie in its lidar frame, at T_match_neighbour[i] from the candidate
// keyframe. Deterministic (the RANSAC sampler has a fixed seed).
KeypointSeed keypointSeed(const KeyframeKeypoints& query, const std::vector<KeyframeKeypointsPtr>& neighbours,
                          const std::vector<Eigen::Isometry3d>& T_match_neighbour, const KeypointSeedConfig& config);

// Two relative poses within agree_translation and agree_rotation_deg of each other.
bool posesAgree(const Eigen::Isometry3d& a, const Eigen::Isometry3d& b, const KeypointSeedConfig& config);

}  // namespace adit
