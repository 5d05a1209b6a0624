#include "loop/loop_verifier.hpp"

#include "loop/voxel_filter.hpp"

namespace adit {

std::vector<Eigen::Vector3f> buildSubmap(const std::vector<SubmapPiece>& pieces, double voxel) {
  std::vector<Eigen::Vector3f> merged;
  for (const SubmapPiece& piece : pieces) {
    if (!piece.cloud) continue;
    const Eigen::Isometry3f T = piece.T_match_keyframe.cast<float>();
    for (const Eigen::Vector3f& p : *piece.cloud) merged.push_back(T * p);
  }
  return voxelDownsample(merged, voxel);
}

// A tight fit, converged or not: an alignment still sliding along an unconstrained direction fits tightly too,
// and is reported as degenerate rather than as a poor fit.
bool fitsTightly(const IcpResult& r, const LoopVerifierConfig& config) {
  return r.rms <= config.max_rms && r.inlier_ratio >= config.min_inlier_ratio;
}

bool pinsEveryDirection(const FitObservability& fit, const LoopVerifierConfig& config) {
  return fit.weakestTranslationRatio() >= config.min_eigenvalue_ratio && fit.rotation_sigma_rad <= config.max_rotation_sigma;
}

bool pinsAllButOneTranslation(const FitObservability& fit, const LoopVerifierConfig& config) {
  return fit.middleTranslationRatio() >= config.min_eigenvalue_ratio && fit.rotation_sigma_rad <= config.max_rotation_sigma;
}

std::vector<Eigen::Vector3f> querySource(const std::vector<Eigen::Vector3f>& query_cloud, const LoopVerifierConfig& config) {
  return voxelDownsample(query_cloud, config.query_voxel);
}

LoopVerification verifyLoop(const std::vector<Eigen::Vector3f>& query_cloud,
                            const std::vector<Eigen::Vector3f>& submap,
                            const std::vector<Eigen::Isometry3d>& seeds, const LoopVerifierConfig& config) {
  const PlaneTarget target(submap, config.icp);
  return verifyLoopAgainst(target, querySource(query_cloud, config), seeds, config);
}

LoopVerification verifyLoopAgainst(const PlaneTarget& target, const std::vector<Eigen::Vector3f>& source,
                                   const std::vector<Eigen::Isometry3d>& seeds, const LoopVerifierConfig& config) {
  LoopVerification out;
  if (source.size() < 30 || target.planarPoints() < 30 || seeds.empty()) return out;

  out.verdict = LoopVerdict::kPoorFitness;
  for (std::size_t i = 0; i < seeds.size(); ++i) {
    const IcpResult r = alignPointToPlane(target, source, seeds[i], config.icp);
    const bool better = out.seed < 0 || r.inlier_ratio > out.icp.inlier_ratio;
    if (fitsTightly(r, config) || better) {
      out.icp = r;
      out.seed = static_cast<int>(i);
      out.T_match_query = r.T_target_source;
    }
    if (fitsTightly(r, config)) break;
  }
  if (!fitsTightly(out.icp, config)) return out;
  if (!pinsEveryDirection(out.icp.observability, config))
    out.verdict = LoopVerdict::kDegenerate;
  else if (out.icp.converged)
    out.verdict = LoopVerdict::kAccepted;
  return out;
}

const char* toString(LoopVerdict verdict) {
  switch (verdict) {
    case LoopVerdict::kAccepted: return "accepted";
    case LoopVerdict::kTooFewPoints: return "too few points";
    case LoopVerdict::kPoorFitness: return "poor fitness";
    case LoopVerdict::kDegenerate: return "degenerate";
  }
  return "unknown";
}

}  // namespace adit
