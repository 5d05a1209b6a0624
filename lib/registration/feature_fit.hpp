// Local geometry of a few map neighbours: a line (edge) by PCA, or a plane by least squares with an outlier
// check. Used by the mapper to turn nearest map points into point-to-line / point-to-plane targets.
#pragma once

#include <Eigen/Core>

#include <optional>
#include <vector>

namespace adit {

struct LineFit {
  Eigen::Vector3d centroid;
  Eigen::Vector3d direction;  // unit
};

struct PlaneFit {
  Eigen::Vector3d normal;  // unit
  double offset = 0.0;     // normal . x + offset = 0
};

// A line when the largest covariance eigenvalue exceeds min_eigen_ratio times the second (A-LOAM: 3).
std::optional<LineFit> fitLine(const std::vector<Eigen::Vector3d>& points, double min_eigen_ratio);

// The total-least-squares plane (smallest covariance eigenvector through the centroid). Rejected when any
// point is farther than max_point_distance from it (not one plane: a corner, a step, clutter) or when the
// points are nearly collinear (the normal would be arbitrary). With min_spread_ratio > 0 also rejected when
// the points lie along one curve: the middle covariance eigenvalue below min_spread_ratio times the largest.
// A few points of one lidar ring on a curved wall are such a curve, and the plane through them is the
// ring's own plane, not the wall's (see mapping.plane_min_spread).
std::optional<PlaneFit> fitPlane(const std::vector<Eigen::Vector3d>& points, double max_point_distance,
                                 double min_spread_ratio = 0.0);

}  // namespace adit
