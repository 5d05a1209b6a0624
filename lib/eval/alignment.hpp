// Umeyama least-squares alignment of an estimated trajectory onto the ground truth (evo's
// geometry.umeyama_alignment and PosePath3D.align).
#pragma once

#include "core/types.hpp"

#include <string>
#include <vector>

namespace adit::eval {

enum class AlignMode { kNone, kSE3, kSim3 };
AlignMode parseAlignMode(const std::string& name);  // "none" | "se3" | "sim3"; throws std::invalid_argument
std::string toString(AlignMode mode);

// y ~= scale * R * x + t.
struct Similarity {
  Eigen::Matrix3d rotation = Eigen::Matrix3d::Identity();
  Eigen::Vector3d translation = Eigen::Vector3d::Zero();
  double scale = 1.0;
  // evo refuses to align when the cross-covariance has rank < 2 (all points on a line, or fewer than
  // 2 distinct points). We do not fail: rotation stays identity, scale 1, and translation matches the
  // centroids; this flag says so, and reports print it.
  bool degenerate = false;
};

// Umeyama (PAMI 1991) mapping points x onto points y (same count). with_scale: also solve the scale.
Similarity umeyama(const std::vector<Eigen::Vector3d>& x, const std::vector<Eigen::Vector3d>& y, bool with_scale);

// Solve the alignment of `est` onto `gt` (matched pose by pose) for the mode; kNone gives identity.
Similarity solveAlignment(const Trajectory& gt, const Trajectory& est, AlignMode mode);

// Apply like evo: positions scaled first, then the rigid part left-multiplied:
// p' = R * (s * p) + t, R' = R * R_p.
Trajectory applyAlignment(const Trajectory& est, const Similarity& s);

}  // namespace adit::eval
