#include "loop/keypoint_seed.hpp"

#include "core/geometry.hpp"
#include "features/link3d_match.hpp"
#include "loop/se3.hpp"

#include <set>

namespace adit {

KeypointSeed keypointSeed(const KeyframeKeypoints& query, const std::vector<KeyframeKeypointsPtr>& neighbours,
                          const std::vector<Eigen::Isometry3d>& T_match_neighbour, const KeypointSeedConfig& config) {
  KeypointSeed out;
  if (query.size() < 3) return out;
  LinK3dConfig match_config;
  match_config.bin_tolerance = config.bin_tolerance;
  match_config.min_score = config.min_score;
  const std::vector<LinK3dDescriptor> query_descriptors = query.descriptors();

  // Every neighbour's matched keypoints in the candidate's frame (a = match side, b = query side). One object
  // seen from several neighbours gives several pairs for one query keypoint; inliers count query keypoints.
  std::vector<Eigen::Vector3f> in_match;
  std::vector<LinK3dMatch> pairs;
  for (std::size_t i = 0; i < neighbours.size() && i < T_match_neighbour.size(); ++i) {
    if (!neighbours[i] || neighbours[i]->empty()) continue;
    const KeyframeKeypoints& neighbour = *neighbours[i];
    const Eigen::Isometry3f T = T_match_neighbour[i].cast<float>();
    for (const LinK3dMatch& m : matchLinK3d(query_descriptors, neighbour.descriptors(), match_config)) {
      pairs.push_back({static_cast<int>(in_match.size()), m.a, m.score});
      in_match.push_back(T * neighbour.points()[static_cast<std::size_t>(m.b)]);
    }
  }
  out.matches = static_cast<int>(pairs.size());
  if (pairs.size() < 3) return out;

  RansacConfig ransac;
  ransac.iterations = config.ransac_iterations;
  ransac.inlier_threshold = config.inlier_threshold;
  ransac.min_inliers = 3;  // judged below on distinct query keypoints
  const RansacResult r = estimateTransformRansac(in_match, query.points(), pairs, ransac);
  if (!r.ok || !r.T_a_b.matrix().allFinite()) return out;
  std::set<int> agreeing;
  for (const LinK3dMatch& m : r.inliers) agreeing.insert(m.b);
  out.inliers = static_cast<int>(agreeing.size());
  out.T_match_query = orthonormal(r.T_a_b);
  out.ok = out.inliers >= config.min_inliers;
  return out;
}

bool posesAgree(const Eigen::Isometry3d& a, const Eigen::Isometry3d& b, const KeypointSeedConfig& config) {
  const Eigen::Isometry3d d = a.inverse() * b;
  return translationNorm(d) < config.agree_translation &&
         rotationAngle(d) < config.agree_rotation_deg * 3.14159265358979323846 / 180.0;
}

}  // namespace adit
