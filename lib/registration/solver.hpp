// One correspondence round of point-to-line / point-to-plane registration, shared by scan-to-scan odometry
// and scan-to-map mapping: a hand-written 6-DoF Gauss-Newton with robust weights (IRLS) and analytic
// Jacobians over T = T0 * Exp(xi) (pose_increment.hpp). The caller finds correspondences at a linearisation
// pose T0; this solves for the pose, measures degeneracy from the information matrix and, if asked, holds
// degenerate directions to a motion-model prior (a directional residual, then Zhang 2016's solution
// remapping). The caller recomputes correspondences at the new pose and calls again (outer loop).
#pragma once

#include "core/config_table.hpp"
#include "core/types.hpp"
#include "registration/correspondences.hpp"
#include "registration/degeneracy.hpp"

#include <string>

namespace adit {

struct RegistrationConfig {
  // Gauss-Newton iterations per outer round (the key kept its name from the Ceres solver it replaced; a
  // round also stops when a step moves the pose by less than 1e-6 m / 1e-7 rad). Correspondences are fixed
  // inside a round, so a few suffice.
  int max_solver_iterations = 5;
  // Robust loss: "huber", "cauchy" or "none"; scale in metres of residual. 0.1 m is A-LOAM's Huber scale:
  // residuals beyond ~10 cm (wrong correspondences, moving objects) lose influence.
  std::string loss = "huber";
  double loss_scale_m = 0.1;
  // Fewer correspondences than this and the round is declared failed (the pose is not trusted).
  int min_correspondences = 10;
  // Standard deviation of a point-to-feature residual (m); scales J^T J into an information matrix.
  double point_sigma_m = 0.05;
  // Degenerate when an eigenvalue < ratio * largest eigenvalue of its block (see degeneracy.hpp). Measured
  // on synthetic 16-beam sweeps: featureless corridor axis 0.004, box room and pillared roadway >= 0.09
  // (translation); roadway roll 0.008 of yaw while well determined, hence the lower rotation ratio.
  double degeneracy_ratio_translation = 0.02;
  double degeneracy_ratio_rotation = 0.001;
  // Hold degenerate directions to the motion-model prior (false reproduces plain A-LOAM).
  bool degeneracy_prior = true;
  // Judge degeneracy from the point-to-plane information only (the covariance still uses all of it). In a
  // smooth arched tunnel (lib/sim "featureless") edge points that slide with the sensor (range noise on the
  // walls, ~180 a sweep before the feature stage's noise floor; ~40 remain on the floor creases and where
  // rings turn over the arch's crown) add fake axial information (5-10% of the largest eigenvalue), so with edges counted the axis is
  // never flagged; planes alone show it (ratio < 0.007).
  // On kitti_mini it also helped (01 worst pair 0.067 -> 0.021 m).
  bool degeneracy_from_planes_only = true;
  // Stiffness of that prior relative to the largest eigenvalue of its block: 1 pins the direction to the
  // prior as firmly as the best-observed direction is pinned by the data (Zhang 2016's solution remapping
  // in effect, but expressed as a residual inside the solve).
  double degeneracy_prior_strength = 1.0;
  // After solving, set the solution's component along each degenerate direction to the prior's (Zhang
  // 2016's solution remapping). The soft prior above alone leaks toward what the measurements say, and the
  // motion model is the previous estimate, so a pull of a few percent a sweep (sliding edge points pull
  // toward zero motion) compounds. Measured (tests/odometry test_sim_featureless, largest axial error in
  // the degenerate zone): 6.4 m with, 7.0 m without; in an earlier variant holding the last motion rather
  // than the averaged velocity it mattered more (0.7 against 8.8 m).
  bool degeneracy_remap = true;
  // Uncertainty of the motion model per sweep, used as the covariance of degenerate directions.
  double prior_sigma_translation_m = 0.1;
  double prior_sigma_rotation_rad = 0.01;
  // Threads of the correspondence search (a fixed partition of the queries, core/chunk_pool.hpp): the result is
  // the same bytes for any count; 2 halves the search's wall time on a 2-core machine.
  int search_threads = 2;
  // A query that moved less than this since its last search in the same registration keeps that search's
  // match (match_reuse.hpp): later rounds re-search only what moved. 0 re-searches every query every round.
  double reuse_match_distance_m = 0.02;
};

// Keys "<prefix>.max_solver_iterations", "<prefix>.loss", ... (prefix "odometry" or "mapping").
ConfigTable<RegistrationConfig> registrationConfigTable(const std::string& prefix);

struct RegistrationResult {
  bool ok = false;  // enough correspondences and a finite solution
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
  Matrix6d information = Matrix6d::Zero();  // measurements only, lidar-frame tangent at `pose`
  DegeneracyReport degeneracy;                // see degeneracy_from_planes_only
  int iterations = 0;
  double final_cost = 0.0;  // 1/2 sum of robust costs (and priors) at the last iterate
  int num_correspondences = 0;
};

// A rotation measured by another sensor (a gyro integrated over the sweep interval): T's rotation is held
// to R with a standard deviation of sigma_rad about each axis, beside the point residuals. `covariance` adds
// the uncertainty of what R was integrated from (rad^2, sweep-frame tangent): an earlier estimate, when the
// reference sweep is not the previous one.
struct RotationPrior {
  Eigen::Matrix3d R = Eigen::Matrix3d::Identity();  // reference_R_sweep
  double sigma_rad = 1e-3;
  Eigen::Matrix3d covariance = Eigen::Matrix3d::Zero();
};
// The prior's information (1/rad^2): the inverse of sigma_rad^2 I + covariance.
Eigen::Matrix3d rotationPriorInformation(const RotationPrior& prior);

// Solves for the pose T (reference_T_sweep) starting at T0. `motion_prior` is the motion model's guess of T,
// used only along degenerate directions; `rotation_prior` (optional) weighs T's rotation in every direction.
RegistrationResult registerStep(const Correspondences& matches, const Eigen::Isometry3d& T0,
                                const Eigen::Isometry3d& motion_prior, const RegistrationConfig& config,
                                const RotationPrior* rotation_prior = nullptr);

// Copies a successful result's covariance (degenerate directions inflated to the prior), eigenvalues,
// degeneracy flags and cost into `out`.
void reportRegistration(const RegistrationResult& result, const RegistrationConfig& config, PoseEstimate& out);

}  // namespace adit
