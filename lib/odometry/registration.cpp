#include "odometry/registration.hpp"

#include "odometry/pose_increment.hpp"
#include "odometry/residuals.hpp"

#include <ceres/ceres.h>

#include <algorithm>
#include <memory>

namespace adit {
namespace {

std::unique_ptr<ceres::LossFunction> makeLoss(const RegistrationConfig& c) {
  if (c.loss == "cauchy") return std::make_unique<ceres::CauchyLoss>(c.loss_scale_m);
  if (c.loss == "none") return nullptr;
  return std::make_unique<ceres::HuberLoss>(c.loss_scale_m);
}

// Adds one residual block per correspondence, with the geometry moved into the frame of T0.
std::vector<ceres::ResidualBlockId> addMeasurements(ceres::Problem& problem, double* xi, const Correspondences& m,
                                                    const Eigen::Isometry3d& T0, ceres::LossFunction* loss) {
  std::vector<ceres::ResidualBlockId> ids;
  ids.reserve(m.size());
  const Eigen::Isometry3d T0_inv = T0.inverse();
  for (const LineMatch& l : m.lines) {
    auto* f = new PointToLineResidual{l.point, T0_inv * l.on_line, T0_inv.linear() * l.direction};
    ids.push_back(problem.AddResidualBlock(new ceres::AutoDiffCostFunction<PointToLineResidual, 3, 6>(f), loss, xi));
  }
  for (const PlaneMatch& p : m.planes) {
    const Eigen::Vector3d n = T0.linear().transpose() * p.normal;
    auto* f = new PointToPlaneResidual{p.point, n, p.normal.dot(T0.translation()) + p.offset};
    ids.push_back(problem.AddResidualBlock(new ceres::AutoDiffCostFunction<PointToPlaneResidual, 1, 6>(f), loss, xi));
  }
  return ids;
}

// J^T J / sigma^2 of the given residual blocks at the current parameter value (robust weights applied).
Matrix6d informationOf(ceres::Problem& problem, const std::vector<ceres::ResidualBlockId>& ids, double sigma) {
  ceres::Problem::EvaluateOptions options;
  options.residual_blocks = ids;
  options.apply_loss_function = true;
  options.num_threads = 1;
  ceres::CRSMatrix J;
  Matrix6d H = Matrix6d::Zero();
  if (ids.empty() || !problem.Evaluate(options, nullptr, nullptr, nullptr, &J)) return H;
  for (int row = 0; row < J.num_rows; ++row) {
    Vector6d g = Vector6d::Zero();
    for (int k = J.rows[row]; k < J.rows[row + 1]; ++k) g[J.cols[k]] = J.values[k];
    H.noalias() += g * g.transpose();
  }
  return H / (sigma * sigma);
}

// Residuals holding each degenerate eigen-direction of a block to the prior increment.
void addDirectionalPriors(ceres::Problem& problem, double* xi, const DegeneracyReport& d, const Vector6d& target,
                          const RegistrationConfig& c) {
  for (int block = 0; block < 2; ++block) {
    const auto& degenerate = block == 0 ? d.translation_degenerate : d.rotation_degenerate;
    const Eigen::Matrix3d& dirs = block == 0 ? d.translation_directions : d.rotation_directions;
    const double largest = block == 0 ? d.translation_eigenvalues[2] : d.rotation_eigenvalues[2];
    if (!(largest > 0.0)) continue;  // nothing observed at all: the solver will not move xi anyway
    for (int i = 0; i < 3; ++i) {
      if (!degenerate[i]) continue;
      Vector6d v = Vector6d::Zero();
      v.segment<3>(3 * block) = dirs.col(i);
      // Residuals are in metres with implicit sigma = point_sigma; weight^2 / sigma^2 = strength * largest.
      const double weight = std::sqrt(c.degeneracy_prior_strength * largest) * c.point_sigma_m;
      problem.AddResidualBlock(new ceres::AutoDiffCostFunction<DirectionalPriorResidual, 1, 6>(
                                   new DirectionalPriorResidual{v, target, weight}),
                               nullptr, xi);
    }
  }
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
  t.add("max_solver_iterations", &G::max_solver_iterations, between(1, 1000), "", "Ceres iterations per correspondence round")
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
   .add("prior_sigma_rotation_rad", &G::prior_sigma_rotation_rad, above(0), "rad", "same for rotation");
  return t;
}

RegistrationResult registerStep(const Correspondences& matches, const Eigen::Isometry3d& T0,
                                const Eigen::Isometry3d& motion_prior, const RegistrationConfig& config) {
  RegistrationResult result;
  result.pose = T0;
  result.num_correspondences = static_cast<int>(matches.size());
  if (!isFinitePose(T0) || result.num_correspondences < std::max(1, config.min_correspondences)) return result;

  double xi[6] = {0, 0, 0, 0, 0, 0};
  ceres::Problem::Options problem_options;
  problem_options.loss_function_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;
  ceres::Problem problem(problem_options);
  const std::unique_ptr<ceres::LossFunction> loss = makeLoss(config);
  const auto ids = addMeasurements(problem, xi, matches, T0, loss.get());
  const std::vector<ceres::ResidualBlockId> plane_ids(ids.begin() + static_cast<long>(matches.lines.size()), ids.end());
  const auto& degeneracy_ids = config.degeneracy_from_planes_only ? plane_ids : ids;

  // Degeneracy at the linearisation point decides where the motion prior applies during this round.
  const Matrix6d H0 = informationOf(problem, degeneracy_ids, config.point_sigma_m);
  const DegeneracyReport d0 = analyzeDegeneracy(H0, config.degeneracy_ratio_translation, config.degeneracy_ratio_rotation);
  const bool hold = config.degeneracy_prior && d0.flags != 0 && isFinitePose(motion_prior);
  const Vector6d target = hold ? incrementBetween(T0, motion_prior) : Vector6d::Zero();
  if (hold) addDirectionalPriors(problem, xi, d0, target, config);

  ceres::Solver::Options options;
  options.linear_solver_type = ceres::DENSE_QR;
  options.max_num_iterations = std::max(1, config.max_solver_iterations);
  options.num_threads = 1;
  options.logging_type = ceres::SILENT;
  options.minimizer_progress_to_stdout = false;
  ceres::Solver::Summary summary;
  ceres::Solve(options, &problem, &summary);

  Vector6d solution = Eigen::Map<const Vector6d>(xi);
  if (!solution.allFinite()) return result;
  if (hold && config.degeneracy_remap) {
    remapDegenerate(solution, d0, target);
    std::copy(solution.data(), solution.data() + 6, xi);  // the information below is evaluated there
  }
  // Report information and degeneracy at the solution, from the measurements only.
  result.information = informationOf(problem, ids, config.point_sigma_m);
  const Matrix6d H = config.degeneracy_from_planes_only ? informationOf(problem, plane_ids, config.point_sigma_m)
                                                        : result.information;
  result.degeneracy = analyzeDegeneracy(H, config.degeneracy_ratio_translation, config.degeneracy_ratio_rotation);
  result.pose = applyIncrement(T0, solution);
  result.iterations = static_cast<int>(summary.iterations.size());
  result.final_cost = summary.final_cost;
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
