// Resolving a fit that is tight but slides along one direction. A sweep on a straight roadway pins the
// cross-section and the heading, but arches and bolt rows repeat every metre or two, so ICP leaves the position
// along the roadway open (loop verification calls that degenerate and refuses it). This searches that one
// direction instead: ICP from seeds spaced along it across the candidate's submap, each fit scored by its share
// of inliers. The best fit is kept only when it is tight, leaves no other direction weak, and beats every fit
// elsewhere along the line by a margin: where the roadway repeats, it refuses.
#pragma once

#include "core/config_table.hpp"
#include "loop/loop_verifier.hpp"

#include <vector>

namespace adit {

struct AxialSearchConfig {
  bool enabled = true;
  double range = 15.0;        // m searched on each side of the degenerate fit
  double step = 0.5;          // m between seeds (within the ICP's coarse gate of each other)
  int seed_iterations = 4;    // Gauss-Newton iterations per phase from each seed before the best are refined
  int refined = 3;            // best places refined with the full ICP before they are compared
  double separation = 0.6;    // m along the line: fits farther apart are different places
  double min_inlier_ratio = 0.85;  // the best fit's share of inliers
  double margin = 0.08;       // over the best fit at another place
  // A fit whose rotation is weak (loop.verifier.max_rotation_sigma) is refused: the search resolves one
  // translation, not a rotation.
};

const ConfigTable<AxialSearchConfig>& axialSearchConfigTable();

struct AxialSearchResult {
  bool resolved = false;
  Eigen::Isometry3d T_target_source = Eigen::Isometry3d::Identity();
  IcpResult icp;               // the best fit
  double runner_up = 0.0;      // inlier ratio of the best fit at another place (0: none)
  Eigen::Vector3d axis = Eigen::Vector3d::Zero();  // the searched direction (target frame; zero: not searched)
  const char* refusal = "";    // why not resolved
};

// `fit`: a tight fit with one weak direction (verifyLoopAgainst's kDegenerate), of `source` against `target`.
AxialSearchResult searchWeakDirection(const PlaneTarget& target, const std::vector<Eigen::Vector3f>& source,
                                      const IcpResult& fit, const LoopVerifierConfig& verifier,
                                      const AxialSearchConfig& config);

}  // namespace adit
