#include "map/axial_search.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>

namespace adit {
namespace {

// The translation along which the fit is weakest (left perturbation: in the target frame); zero when a second
// translation is weak too or a rotation is (FitObservability, with the loop verifier's thresholds).
Eigen::Vector3d weakTranslation(const IcpResult& fit, const LoopVerifierConfig& verifier) {
  if (!pinsAllButOneTranslation(fit.observability, verifier)) return Eigen::Vector3d::Zero();
  return fit.observability.weakestTranslation().normalized();
}

struct Place {
  IcpResult icp;
  double along = 0.0;  // m along the weak direction from the degenerate fit
};

bool better(const Place& a, const Place& b) {
  if (a.icp.inlier_ratio != b.icp.inlier_ratio) return a.icp.inlier_ratio > b.icp.inlier_ratio;
  return a.icp.rms < b.icp.rms;
}

// ICP from seeds every config.step along `axis`, a few iterations each: the fits, best first.
std::vector<Place> sweepLine(const PlaneTarget& target, const std::vector<Eigen::Vector3f>& source,
                             const Eigen::Isometry3d& T_fit, const Eigen::Vector3d& axis, const IcpConfig& icp,
                             const AxialSearchConfig& config) {
  IcpConfig quick = icp;
  quick.max_iterations = config.seed_iterations;
  std::vector<Place> places;
  const int n = static_cast<int>(std::floor(config.range / config.step));
  for (int i = -n; i <= n; ++i) {
    Eigen::Isometry3d seed = T_fit;
    seed.pretranslate(axis * (i * config.step));
    Place p;
    p.icp = alignPointToPlane(target, source, seed, quick);
    p.along = axis.dot(p.icp.T_target_source.translation() - T_fit.translation());
    places.push_back(p);
  }
  std::stable_sort(places.begin(), places.end(), better);
  return places;
}

// The best `count` places at least `separation` apart, each refined by the full ICP, best first.
std::vector<Place> refineDistinct(const PlaneTarget& target, const std::vector<Eigen::Vector3f>& source,
                                  const std::vector<Place>& places, const Eigen::Vector3d& axis,
                                  const Eigen::Isometry3d& T_fit, const IcpConfig& icp, const AxialSearchConfig& config) {
  std::vector<Place> distinct;
  for (const Place& p : places) {
    if (static_cast<int>(distinct.size()) >= config.refined) break;
    const bool near = std::any_of(distinct.begin(), distinct.end(),
                                  [&](const Place& d) { return std::abs(d.along - p.along) < config.separation; });
    if (near) continue;
    distinct.push_back(p);
  }
  for (Place& p : distinct) {
    p.icp = alignPointToPlane(target, source, p.icp.T_target_source, icp);
    p.along = axis.dot(p.icp.T_target_source.translation() - T_fit.translation());
  }
  std::stable_sort(distinct.begin(), distinct.end(), better);
  return distinct;
}

}  // namespace

const ConfigTable<AxialSearchConfig>& axialSearchConfigTable() {
  using A = AxialSearchConfig;
  static const ConfigTable<A> table = [] {
    ConfigTable<A> t("reloc.axial");
    t.add("enabled", &A::enabled, anyValue(), "", "search a fit that is tight but weak along one translation (a straight roadway) along that direction")
     .add("range", &A::range, above(0), "m", "searched on each side of the weak fit")
     .add("step", &A::step, above(0), "m", "between the seeds of the search")
     .add("seed_iterations", &A::seed_iterations, between(1, 100), "", "ICP iterations per phase from each seed")
     .add("refined", &A::refined, between(1, 100), "", "best distinct places refined by the full ICP")
     .add("separation", &A::separation, above(0), "m", "fits farther apart along the line are different places")
     .add("min_inlier_ratio", &A::min_inlier_ratio, between(0, 1), "", "the best fit's share of inliers")
     .add("margin", &A::margin, between(0, 1), "", "inlier ratio the best fit must have over the best fit elsewhere on the line");
    return t;
  }();
  return table;
}

AxialSearchResult searchWeakDirection(const PlaneTarget& target, const std::vector<Eigen::Vector3f>& source,
                                      const IcpResult& fit, const LoopVerifierConfig& verifier,
                                      const AxialSearchConfig& config) {
  AxialSearchResult out;
  const Eigen::Vector3d axis = weakTranslation(fit, verifier);
  if (axis.isZero()) {
    out.refusal = "weak";
    return out;
  }
  out.axis = axis;
  const Eigen::Isometry3d T_fit = fit.T_target_source;
  const std::vector<Place> line = sweepLine(target, source, T_fit, axis, verifier.icp, config);
  const std::vector<Place> places = refineDistinct(target, source, line, axis, T_fit, verifier.icp, config);
  if (places.empty()) return out;
  const Place& best = places.front();
  out.icp = best.icp;
  out.T_target_source = best.icp.T_target_source;
  // Elsewhere: the refined places and, stricter still, the seeds' own (less converged) fits.
  for (const std::vector<Place>* list : {&places, &line})
    for (const Place& p : *list)
      if (std::abs(p.along - best.along) >= config.separation) out.runner_up = std::max(out.runner_up, p.icp.inlier_ratio);
  if (!fitsTightly(best.icp, verifier) || !best.icp.converged || best.icp.inlier_ratio < config.min_inlier_ratio)
    out.refusal = "loose";
  else if (weakTranslation(best.icp, verifier).isZero())
    out.refusal = "weak";
  else if (best.icp.inlier_ratio - out.runner_up < config.margin)
    out.refusal = "ambiguous";
  else
    out.resolved = true;
  return out;
}

}  // namespace adit
