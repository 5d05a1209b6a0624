#include "registration/solver.hpp"

#include "registration/jacobians.hpp"
#include "registration/pose_increment.hpp"
#include "registration/robust_loss.hpp"

#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>

#include <algorithm>
#include <cmath>

namespace adit {
namespace {

// A line or plane moved into the frame of T0, where the residual of source point p is a function of xi alone.
struct LocalLine {
  Eigen::Vector3d p, a, u;
};
struct LocalPlane {
  Eigen::Vector3d p, n;
  double c;
};
struct LocalProblem {
  std::vector<LocalLine> lines;
  std::vector<LocalPlane> planes;
};

LocalProblem toLocal(const Correspondences& m, const Eigen::Isometry3d& T0) {
  LocalProblem out;
  out.lines.reserve(m.lines.size());
  out.planes.reserve(m.planes.size());
  const Eigen::Isometry3d T0_inv = T0.inverse();
  for (const LineMatch& l : m.lines) out.lines.push_back({l.point, T0_inv * l.on_line, T0_inv.linear() * l.direction});
  for (const PlaneMatch& p : m.planes)
    out.planes.push_back({p.point, T0.linear().transpose() * p.normal, p.normal.dot(T0.translation()) + p.offset});
  return out;
}

// Weighted normal equations at xi: H = sum w J^T J, g = sum w J^T r, cost = 1/2 sum rho(|r|^2); the planes'
// share of H kept apart for the degeneracy test.
struct Linearisation {
  Matrix6d H = Matrix6d::Zero();
  Matrix6d H_planes = Matrix6d::Zero();
  Vector6d g = Vector6d::Zero();
  double cost = 0.0;
};

Linearisation linearise(const LocalProblem& problem, const Vector6d& xi, const RobustKernel& kernel) {
  Linearisation lin;
  const IncrementFrame frame(xi);
  for (const LocalPlane& pl : problem.planes) {
    const double r = planeResidual(pl.n, pl.c, frame.apply(pl.p));
    const double w = kernel.weight(r * r);
    const Row6d J = frame.planeRow(pl.n, pl.p);
    lin.H_planes.noalias() += (w * J.transpose()) * J;
    lin.g.noalias() += (w * r) * J.transpose();
    lin.cost += 0.5 * kernel.cost(r * r);
  }
  Matrix6d H_lines = Matrix6d::Zero();
  for (const LocalLine& l : problem.lines) {
    const Eigen::Vector3d r = lineResidual(l.a, l.u, frame.apply(l.p));
    const double s = r.squaredNorm();
    const double w = kernel.weight(s);
    const Matrix36d J = frame.lineJacobian(l.u, l.p);
    H_lines.noalias() += (w * J.transpose()) * J;
    lin.g.noalias() += w * (J.transpose() * r);
    lin.cost += 0.5 * kernel.cost(s);
  }
  lin.H = lin.H_planes + H_lines;
  return lin;
}

// The residuals holding a direction v of the increment to a target value: weight * (v . xi - target).
// Degenerate eigen-directions of a block are held to the motion model's increment with
// weight^2 / sigma^2 = strength * largest eigenvalue of the block; a measured rotation holds each rotation
// axis with weight = sigma / its own sigma (sigma: the point residuals', so both share one scale).
struct DirectionalPrior {
  Vector6d v;
  double weight;
  double target = 0.0;
};

std::vector<DirectionalPrior> directionalPriors(const DegeneracyReport& d, const RegistrationConfig& c,
                                               const Vector6d& target) {
  std::vector<DirectionalPrior> priors;
  for (int block = 0; block < 2; ++block) {
    const auto& degenerate = block == 0 ? d.translation_degenerate : d.rotation_degenerate;
    const Eigen::Matrix3d& dirs = block == 0 ? d.translation_directions : d.rotation_directions;
    const double largest = block == 0 ? d.translation_eigenvalues[2] : d.rotation_eigenvalues[2];
    if (!(largest > 0.0)) continue;  // nothing observed at all: the solver will not move xi anyway
    for (int i = 0; i < 3; ++i) {
      if (!degenerate[i]) continue;
      Vector6d v = Vector6d::Zero();
      v.segment<3>(3 * block) = dirs.col(i);
      priors.push_back({v, std::sqrt(c.degeneracy_prior_strength * largest) * c.point_sigma_m, v.dot(target)});
    }
  }
  return priors;
}

// The rotation prior's three axes at the linearisation pose T0: T0 * Exp(xi) has R0 * exp(phi), so phi
// is held to log(R0^T R) about each axis.
void addRotationPrior(const RotationPrior& prior, const Eigen::Isometry3d& T0, const RegistrationConfig& c,
                      std::vector<DirectionalPrior>& priors) {
  const Eigen::AngleAxisd aa(T0.linear().transpose() * prior.R);
  const Eigen::Vector3d phi = aa.angle() * aa.axis();
  if (prior.covariance.isZero()) {  // isotropic: one prior per axis
    for (int i = 0; i < 3; ++i) {
      Vector6d v = Vector6d::Zero();
      v[3 + i] = 1.0;
      priors.push_back({v, c.point_sigma_m / prior.sigma_rad, phi[i]});
    }
    return;
  }
  // One prior per principal direction of the information (weights in the solver's units: point_sigma / sigma).
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig(rotationPriorInformation(prior));
  for (int i = 0; i < 3; ++i) {
    const Eigen::Vector3d u = eig.eigenvectors().col(i);
    Vector6d v = Vector6d::Zero();
    v.tail<3>() = u;
    priors.push_back({v, c.point_sigma_m * std::sqrt(std::max(0.0, eig.eigenvalues()[i])), u.dot(phi)});
  }
}

// The measurements' normal equations plus the priors' at xi.
Linearisation withPriors(Linearisation lin, const std::vector<DirectionalPrior>& priors, const Vector6d& xi) {
  for (const DirectionalPrior& p : priors) {
    const double r = p.weight * (p.v.dot(xi) - p.target);
    lin.H.noalias() += (p.weight * p.weight) * p.v * p.v.transpose();
    lin.g.noalias() += (p.weight * r) * p.v;
    lin.cost += 0.5 * r * r;
  }
  return lin;
}

struct Solution {
  Vector6d xi = Vector6d::Zero();
  Linearisation measurements;  // at xi, priors excluded (what information and degeneracy are reported from)
  double cost = 0.0;           // with priors
  int iterations = 0;
};

// Gauss-Newton from xi = 0 (measurements linearised there: at_zero) with the correspondences fixed. A step
// that raises the cost is halved (at most a few times) rather than taken: Levenberg-Marquardt's safety at the
// price of one more linearisation.
Solution gaussNewton(const LocalProblem& problem, const Linearisation& at_zero,
                     const std::vector<DirectionalPrior>& priors, const RobustKernel& kernel, int max_iterations) {
  Solution s;
  s.measurements = at_zero;
  Linearisation lin = withPriors(at_zero, priors, s.xi);
  for (int it = 0; it < max_iterations; ++it) {
    ++s.iterations;
    const Vector6d step = -(lin.H + 1e-12 * Matrix6d::Identity()).ldlt().solve(lin.g);
    if (!step.allFinite()) break;
    Vector6d next = s.xi + step;
    Linearisation next_meas = linearise(problem, next, kernel);
    Linearisation next_lin = withPriors(next_meas, priors, next);
    for (int halvings = 0; halvings < 4 && next_lin.cost > lin.cost; ++halvings) {
      next = s.xi + (next - s.xi) * 0.5;
      next_meas = linearise(problem, next, kernel);
      next_lin = withPriors(next_meas, priors, next);
    }
    if (next_lin.cost > lin.cost) break;  // no descent along the Gauss-Newton direction: xi is the minimum
    const Vector6d moved = next - s.xi;
    s.xi = next;
    s.measurements = next_meas;
    lin = next_lin;
    if (moved.head<3>().norm() < 1e-6 && moved.tail<3>().norm() < 1e-7) break;
  }
  s.cost = lin.cost;
  return s;
}

// Zhang 2016's solution remapping: the solution's component along each degenerate eigen-direction is
// replaced by the prior's. Measurements there are too weak to trust, and a soft prior still leaks toward
// whatever they say; the motion model is the previous estimate, so a leak of a few percent per sweep
// compounds into an exponential decay of the velocity along a featureless roadway.
void remapDegenerate(Vector6d& xi, const DegeneracyReport& d, const Vector6d& target) {
  for (int block = 0; block < 2; ++block) {
    const auto& degenerate = block == 0 ? d.translation_degenerate : d.rotation_degenerate;
    const Eigen::Matrix3d& dirs = block == 0 ? d.translation_directions : d.rotation_directions;
    for (int i = 0; i < 3; ++i) {
      if (!degenerate[i]) continue;
      const Eigen::Vector3d v = dirs.col(i);
      xi.segment<3>(3 * block) += v * v.dot(target.segment<3>(3 * block) - xi.segment<3>(3 * block));
    }
  }
}

}  // namespace

ConfigTable<RegistrationConfig> registrationConfigTable(const std::string& prefix) {
  using G = RegistrationConfig;
  ConfigTable<G> t(prefix);
  t.add("max_solver_iterations", &G::max_solver_iterations, between(1, 1000), "", "Gauss-Newton iterations per correspondence round")
   .add("loss", &G::loss, oneOf({"huber", "cauchy", "none"}), "", "robust loss of the residuals")
   .add("loss_scale_m", &G::loss_scale_m, above(0), "m", "scale of the robust loss (A-LOAM's Huber: 0.1)")
   .add("min_correspondences", &G::min_correspondences, between(1, 1000000), "", "fewer and the round fails (pose not trusted)")
   .add("point_sigma_m", &G::point_sigma_m, above(0), "m", "sigma of a point-to-feature residual (scales the information matrix)")
   .add("degeneracy_ratio_translation", &G::degeneracy_ratio_translation, between(0, 1), "", "degenerate when an eigenvalue < ratio * largest (translation block)")
   .add("degeneracy_ratio_rotation", &G::degeneracy_ratio_rotation, between(0, 1), "", "same for the rotation block")
   .add("degeneracy_prior", &G::degeneracy_prior, anyValue(), "", "hold degenerate directions to the motion model (false: plain A-LOAM)")
   .add("degeneracy_from_planes_only", &G::degeneracy_from_planes_only, anyValue(), "", "judge degeneracy from point-to-plane information only")
   .add("degeneracy_prior_strength", &G::degeneracy_prior_strength, above(0), "", "stiffness of that prior relative to the largest eigenvalue")
   .add("degeneracy_remap", &G::degeneracy_remap, anyValue(), "", "set the solution along degenerate directions to the prior's (Zhang 2016)")
   .add("prior_sigma_translation_m", &G::prior_sigma_translation_m, above(0), "m", "motion-model uncertainty per sweep (covariance of degenerate directions)")
   .add("prior_sigma_rotation_rad", &G::prior_sigma_rotation_rad, above(0), "rad", "same for rotation")
   .add("search_threads", &G::search_threads, between(1, 64), "threads", "threads of the correspondence search (same result for any count)")
   .add("reuse_match_distance_m", &G::reuse_match_distance_m, atLeast(0), "m", "a query that moved less than this since its last search in the sweep keeps that match (0: search every round)");
  return t;
}

Eigen::Matrix3d rotationPriorInformation(const RotationPrior& prior) {
  const Eigen::Matrix3d c = prior.sigma_rad * prior.sigma_rad * Eigen::Matrix3d::Identity() + prior.covariance;
  return (0.5 * (c + c.transpose())).ldlt().solve(Eigen::Matrix3d::Identity());
}

RegistrationResult registerStep(const Correspondences& matches, const Eigen::Isometry3d& T0,
                                const Eigen::Isometry3d& motion_prior, const RegistrationConfig& config,
                                const RotationPrior* rotation_prior) {
  RegistrationResult result;
  result.pose = T0;
  result.num_correspondences = static_cast<int>(matches.size());
  if (!isFinitePose(T0) || result.num_correspondences < std::max(1, config.min_correspondences)) return result;

  const LocalProblem problem = toLocal(matches, T0);
  const RobustKernel kernel{robustLossFromName(config.loss), config.loss_scale_m};
  const double info_scale = 1.0 / (config.point_sigma_m * config.point_sigma_m);

  // Degeneracy at the linearisation point decides where the motion prior applies during this round.
  const Linearisation at_T0 = linearise(problem, Vector6d::Zero(), kernel);
  const Matrix6d H0 = (config.degeneracy_from_planes_only ? at_T0.H_planes : at_T0.H) * info_scale;
  const DegeneracyReport d0 = analyzeDegeneracy(H0, config.degeneracy_ratio_translation, config.degeneracy_ratio_rotation);
  const bool hold = config.degeneracy_prior && d0.flags != 0 && isFinitePose(motion_prior);
  const Vector6d target = hold ? incrementBetween(T0, motion_prior) : Vector6d::Zero();
  std::vector<DirectionalPrior> priors = hold ? directionalPriors(d0, config, target) : std::vector<DirectionalPrior>{};
  if (rotation_prior && rotation_prior->R.allFinite() && rotation_prior->sigma_rad > 0.0)
    addRotationPrior(*rotation_prior, T0, config, priors);

  const Solution solved = gaussNewton(problem, at_T0, priors, kernel, std::max(1, config.max_solver_iterations));
  result.iterations = solved.iterations;
  result.final_cost = solved.cost;
  Vector6d solution = solved.xi;
  if (!solution.allFinite()) return result;
  const bool remap = hold && config.degeneracy_remap;
  if (remap) remapDegenerate(solution, d0, target);
  // Report information and degeneracy at the solution, from the measurements only.
  const Linearisation at_solution = remap ? linearise(problem, solution, kernel) : solved.measurements;
  result.information = at_solution.H * info_scale;
  const Matrix6d H = config.degeneracy_from_planes_only ? Matrix6d(at_solution.H_planes * info_scale) : result.information;
  result.degeneracy = analyzeDegeneracy(H, config.degeneracy_ratio_translation, config.degeneracy_ratio_rotation);
  result.pose = applyIncrement(T0, solution);
  result.ok = isFinitePose(result.pose);
  return result;
}

void reportRegistration(const RegistrationResult& r, const RegistrationConfig& config, PoseEstimate& out) {
  out.covariance = covarianceFrom(r.information, r.degeneracy, config.prior_sigma_translation_m,
                                  config.prior_sigma_rotation_rad);
  out.translation_eigenvalues = r.degeneracy.translation_eigenvalues;
  out.rotation_eigenvalues = r.degeneracy.rotation_eigenvalues;
  out.flags |= r.degeneracy.flags;
  out.final_cost = r.final_cost;
}

}  // namespace adit
