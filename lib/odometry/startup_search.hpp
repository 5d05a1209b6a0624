// Start-up search of scan-to-scan odometry: the first registration of a run (or after a reset) has no motion
// history, and a seed at zero motion converges to a wrong local minimum when the vehicle already moves fast
// (kitti_mini 02: 1.5 m between sweeps, registration from the identity settled at 0.49 m and the error was
// carried on by the motion model). Instead, several seeds along the lidar's forward axis are each refined
// and the one whose result explains the most of the sweep wins.
#pragma once

#include "registration/correspondences.hpp"

#include <Eigen/Geometry>

#include <vector>

namespace adit {

// Seeds to try, in order of preference (ties go to the earlier one): `prior` itself, then `prior`'s rotation
// with no translation (if the prior had some), then with the translation along the lidar's x axis (forward)
// of +step, -step, +2 step, -2 step, ... up to +-max_distance_m. step_m <= 0 or max_distance_m < step_m gives the prior alone.
std::vector<Eigen::Isometry3d> startupHypotheses(const Eigen::Isometry3d& prior, double max_distance_m, double step_m);

// Stride of a screen of about screen_points out of `points` (1: every point; screen_points 0: no screen).
std::size_t screenStride(std::size_t points, int screen_points);

// Correspondences whose residual at pose T (reference_T_sweep) is below max_residual_m: how much of the
// sweep a candidate pose explains. Counted, not summed, so a far-off pose with few matches cannot win by
// having small residuals.
int inlierCount(const Correspondences& matches, const Eigen::Isometry3d& T, double max_residual_m);

}  // namespace adit
