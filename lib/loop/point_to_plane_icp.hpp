// Point-to-plane ICP of a source cloud against a target with per-point normals, reporting the fitness and the
// Hessian that says which directions the alignment actually constrains.
#pragma once

#include "core/types.hpp"
#include "loop/fit_observability.hpp"
#include "registration/kdtree.hpp"

#include <memory>
#include <vector>

namespace adit {

struct IcpConfig {
  // Gauss-Newton iterations per phase (coarse, then fine).
  int max_iterations = 30;
  // Correspondence gate (m) of the coarse phase: the seed can be off by a metre along a roadway.
  double coarse_correspondence_distance = 1.5;
  // Correspondence gate (m) of the fine phase, which also defines the inliers reported.
  double fine_correspondence_distance = 0.5;
  // A point-to-plane residual below this (m) counts as an inlier of the final alignment.
  double inlier_residual = 0.1;
  // Neighbours (count) for each target normal, and the largest allowed "surface variation" (smallest PCA
  // eigenvalue over their sum) for the point to count as planar: 0.05 admits rough rock walls, not corners.
  int normal_neighbors = 8;
  double max_surface_variation = 0.05;
  // Stop a phase when the update is below these (m, rad).
  double converged_translation = 1e-4;
  double converged_rotation = 1e-5;
};

struct IcpResult {
  Eigen::Isometry3d T_target_source = Eigen::Isometry3d::Identity();
  bool converged = false;
  int iterations = 0;
  int correspondences = 0;   // fine-phase correspondences in the final iteration
  double rms = 0.0;          // RMS point-to-plane residual of the inliers (m)
  double inlier_ratio = 0.0; // inliers / valid source points
  Matrix6d hessian = Matrix6d::Zero();  // sum of J^T J over inliers, tangent order (t, r), left perturbation
  FitObservability observability;  // which directions the fit pins (from hessian, at rms floored to 1 cm)
};

// A target cloud with a KD-tree and normals, built once and aligned against many times.
class PlaneTarget {
 public:
  PlaneTarget(const std::vector<Eigen::Vector3f>& points, const IcpConfig& config);
  ~PlaneTarget();
  PlaneTarget(const PlaneTarget&) = delete;
  PlaneTarget& operator=(const PlaneTarget&) = delete;
  int planarPoints() const;

  // Nearest planar point within max_distance: its position and unit normal; false if none. `memo` keeps the
  // search's findings for the next call about the same query point as it moves (see NearestMemo): the
  // answers are a fresh search's, fewer searches are made.
  bool nearest(const Eigen::Vector3d& query, double max_distance, Eigen::Vector3d& point, Eigen::Vector3d& normal,
               NearestMemo& memo) const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

IcpResult alignPointToPlane(const PlaneTarget& target, const std::vector<Eigen::Vector3f>& source,
                            const Eigen::Isometry3d& initial_T_target_source, const IcpConfig& config);

}  // namespace adit
