#include "odometry/scan_to_scan.hpp"

#include "registration/feature_fit.hpp"
#include "registration/match_reuse.hpp"
#include "core/chunk_pool.hpp"
#include "core/geometry.hpp"
#include "core/wheel_odom.hpp"
#include "odometry/motion_compensation.hpp"
#include "odometry/startup_search.hpp"
#include "registration/parallel_matching.hpp"
#include "registration/pose_increment.hpp"

#include <algorithm>
#include <cmath>

namespace adit {
namespace {

constexpr std::int32_t kSeedFlags =
    PoseEstimate::kSeededByLinK3d | PoseEstimate::kSeededByImu | PoseEstimate::kSeededByMotionModel;

// Covariance of a sweep whose registration failed: the motion model's uncertainty in every direction.
Matrix6d priorCovariance(const RegistrationConfig& c) {
  Matrix6d cov = Matrix6d::Zero();
  cov.diagonal() << Eigen::Vector3d::Constant(c.prior_sigma_translation_m * c.prior_sigma_translation_m),
      Eigen::Vector3d::Constant(c.prior_sigma_rotation_rad * c.prior_sigma_rotation_rad);
  return cov;
}

}  // namespace

ScanToScanConfig aloamOdometryConfig() {
  ScanToScanConfig s;
  s.registration.degeneracy_prior = false;
  s.use_link3d_seed = false;
  s.line_min_rings = 2;
  s.line_through_all_rings = false;
  s.three_point_planes = true;
  s.plane_through_nearest = false;
  s.compensate_mixed_deskew = false;
  s.outer_iterations = 2;
  s.registration.max_solver_iterations = 4;
  s.registration.reuse_match_distance_m = 0.0;  // A-LOAM searches every round afresh
  s.max_match_distance_m = 5.0;
  s.startup_max_speed_mps = 0.0;
  s.gyro_rotation_sigma_rad = 0.0;  // A-LOAM has no IMU
  s.keep_reference_within_m = 0.0;  // A-LOAM registers against the previous sweep, always
  s.keep_reference_within_rad = 0.0;
  s.standstill.window_sweeps = 0;  // every registration is the pose
  return s;
}

const ConfigTable<AblationConfig>& ablationConfigTable() {
  static const ConfigTable<AblationConfig> table = [] {
    ConfigTable<AblationConfig> t("ablation");
    t.add("aloam", &AblationConfig::aloam, anyValue(), "", "plain A-LOAM defaults for odometry and mapping (the paper's baseline)");
    return t;
  }();
  return table;
}

const ConfigTable<ScanToScanConfig>& scanToScanConfigTable() {
  using S = ScanToScanConfig;
  static const ConfigTable<S> table = [] {
    ConfigTable<S> t("odometry");
    t.nest(&S::registration, registrationConfigTable("odometry"))
     .nest(&S::standstill, standstillConfigTable("odometry.standstill"))
     .add("outer_iterations", &S::outer_iterations, between(1, 100), "", "correspondence rounds per sweep (A-LOAM: 2)")
     .add("max_match_distance_m", &S::max_match_distance_m, above(0), "m", "largest point-to-neighbour distance accepted when matching")
     .add("ring_window", &S::ring_window, between(0, 64), "rings", "rings either side searched for the second line / third plane point")
     .add("plane_neighbours", &S::plane_neighbours, between(3, 100), "points", "nearest previous less-flat points a plane is fitted to")
     .add("plane_max_point_distance_m", &S::plane_max_point_distance_m, above(0), "m", "a plane is rejected if a point is farther from it")
     .add("line_min_rings", &S::line_min_rings, between(2, 64), "rings", "collinear points (one per ring) an edge line needs")
     .add("line_through_all_rings", &S::line_through_all_rings, anyValue(), "", "where 3+ rings see an edge, its line is fitted to them all and checked, not drawn through the nearest two (A-LOAM: false)")
     .add("line_eigen_ratio", &S::line_eigen_ratio, atLeast(1), "", "line if the largest PCA eigenvalue exceeds ratio * the second")
     .add("line_max_point_distance_m", &S::line_max_point_distance_m, above(0), "m", "a line is rejected if a point is farther from it")
     .add("three_point_planes", &S::three_point_planes, anyValue(), "", "A-LOAM's unchecked three-point planes (ablation only)")
     .add("plane_through_nearest", &S::plane_through_nearest, anyValue(), "", "a surface match's plane passes through the nearest previous point, not the neighbours' centroid")
     .add("ring_neighbours", &S::ring_neighbours, between(0, 100), "points", "nearest points per ring added to a plane fit")
     .add("compensate_mixed_deskew", &S::compensate_mixed_deskew, anyValue(), "", "move a raw sweep to its end instant when its neighbour is deskewed")
     .add("use_link3d_seed", &S::use_link3d_seed, anyValue(), "", "seed from LinK3D matches (false: motion model only, A-LOAM)")
     .add("max_velocity_gap_s", &S::max_velocity_gap_s, above(0), "s", "longest gap over which the constant-velocity model extrapolates")
     .add("hold_velocity_time_constant_s", &S::hold_velocity_time_constant_s, atLeast(0), "s", "averaging of the velocity degenerate directions hold to; 0 = last motion")
     .add("hold_velocity_observed_ratio", &S::hold_velocity_observed_ratio, between(0, 1), "", "that average weighs a translation direction fully from this eigenvalue ratio on (all residuals), not at all where degenerate; 0 = unweighted")
     .add("gyro_rotation_sigma_rad", &S::gyro_rotation_sigma_rad, atLeast(0), "rad", "per-sweep sigma of the bias-corrected gyro rotation the registration weighs (0: the gyro only seeds)")
     .add("startup_max_speed_mps", &S::startup_max_speed_mps, atLeast(0), "m/s", "fastest a vehicle may already move when odometry starts (start-up search range; 0 = no search)")
     .add("startup_search_step_m", &S::startup_search_step_m, above(0), "m", "spacing of the start-up search's seeds along the forward axis")
     .add("startup_inlier_distance_m", &S::startup_inlier_distance_m, above(0), "m", "residual below which a correspondence counts for a start-up seed")
     .add("startup_screen_points", &S::startup_screen_points, between(0, 1000000), "points", "sharp and flat points each start-up seed is refined and scored on (every k-th of the sweep's; 0 = all)")
     .add("keep_reference_within_m", &S::keep_reference_within_m, atLeast(0), "m", "a sweep this close to the reference sweep leaves it the registration target (at rest errors do not add up; 0 = always the previous sweep)")
     .add("keep_reference_within_rad", &S::keep_reference_within_rad, atLeast(0), "rad", "and turned less than this from it (0 = always the previous sweep)");
    return t;
  }();
  return table;
}

ScanToScanConfig scanToScanConfigFrom(const Config& c) {
  const bool aloam = ablationConfigTable().read(c).aloam;
  return scanToScanConfigTable().read(c, aloam ? aloamOdometryConfig() : ScanToScanConfig{});
}

ScanToScanOdometry::ScanToScanOdometry(ScanToScanConfig config)
    : config_(std::move(config)),
      pool_(config_.registration.search_threads > 1 ? std::make_shared<ChunkPool>(config_.registration.search_threads)
                                                    : nullptr),
      index_builder_(pool_ ? std::make_shared<SerialWorker>(true) : nullptr),
      standstill_(config_.standstill) {}

void ScanToScanOdometry::reset() { *this = ScanToScanOdometry(config_); }

Vector6d ScanToScanOdometry::lastVelocity() const {
  if (last_gap_us_ <= 0) return Vector6d::Zero();
  return incrementBetween(Eigen::Isometry3d::Identity(), last_motion_) / toSeconds(last_gap_us_);
}

void ScanToScanOdometry::resumeAt(const Eigen::Isometry3d& pose) {
  reset();
  if (pose.matrix().allFinite()) pose_ = pose;
}

bool ScanToScanOdometry::hasVelocity(std::int64_t utime) const {
  const std::int64_t gap = utime - previous_utime_;
  return has_previous_ && last_gap_us_ > 0 && gap > 0;
}

Eigen::Isometry3d ScanToScanOdometry::predictMotion(std::int64_t utime) const {
  const std::int64_t gap = utime - previous_utime_;
  if (!hasVelocity(utime)) return Eigen::Isometry3d::Identity();
  if (toSeconds(gap) > config_.max_velocity_gap_s) return predictHeldMotion(utime);
  return scaleMotion(last_motion_, static_cast<double>(gap) / static_cast<double>(last_gap_us_));
}

Eigen::Isometry3d ScanToScanOdometry::predictHeldMotion(std::int64_t utime) const {
  if (!hasVelocity(utime)) return Eigen::Isometry3d::Identity();
  return applyIncrement(Eigen::Isometry3d::Identity(), held_velocity_ * toSeconds(utime - previous_utime_));
}

void ScanToScanOdometry::updateHeldVelocity(const Eigen::Isometry3d& T_prev_curr, std::int64_t gap_us,
                                            const Matrix6d* information) {
  const double gap_s = toSeconds(gap_us);
  if (!(gap_s > 0.0)) return;
  const Vector6d velocity = incrementBetween(Eigen::Isometry3d::Identity(), T_prev_curr) / gap_s;
  const double tau = config_.hold_velocity_time_constant_s;
  // The first velocity (none known before) is taken as it is; then an exponential average.
  const bool first = last_gap_us_ == 0;
  const double alpha = (first || !(tau > 0.0)) ? 1.0 : 1.0 - std::exp(-gap_s / tau);
  const Vector6d change = velocity - held_velocity_;
  held_velocity_.tail<3>() += alpha * change.tail<3>();
  const double full = config_.hold_velocity_observed_ratio, none = config_.registration.degeneracy_ratio_translation;
  // Observed by every residual (edges too), not only the planes the degeneracy flag is judged from: where
  // arches, bolts and equipment pin the roadway's axis its planes alone look weak (0.02-0.04 of the largest
  // eigenvalue on roadway-loop, where all residuals give 0.22-0.36), and down-weighting those sweeps let the
  // held speed lag the robot's real accelerations (roadway-loop 20 s APE 0.011 -> 0.020 m).
  const DegeneracyReport observed = information ? analyzeDegeneracy(*information, none, 0.0) : DegeneracyReport{};
  const double largest = observed.translation_eigenvalues[2];
  if (first || !information || !(full > none) || !(largest > 0.0)) {
    held_velocity_.head<3>() += alpha * change.head<3>();
    return;
  }
  for (int i = 0; i < 3; ++i) {  // per translation eigen-direction, weighted by how well it was observed
    const Eigen::Vector3d d = observed.translation_directions.col(i);
    const double ratio = observed.translation_eigenvalues[i] / largest;
    const double weight = std::clamp((ratio - none) / (full - none), 0.0, 1.0);
    held_velocity_.head<3>() += d * (alpha * weight * d.dot(change.head<3>()));
  }
}

std::optional<LineFit> ScanToScanOdometry::fitLocalLine(const Eigen::Vector3d& q, double max_sq) const {
  // The nearest previous edge point and the nearest on each ring within ring_window of it: one point per
  // ring, so the line follows the edge across rings. With line_min_rings = 2 the line runs through the
  // nearest point and the nearest point on another ring (A-LOAM); more rings must also be collinear.
  const int j = previous_->corners.nearest(q, max_sq);
  if (j < 0) return std::nullopt;
  const int ring = previous_->corners.ring(j);
  thread_local std::vector<Eigen::Vector3d> pts;  // scratch, reused: no allocation per query
  pts.assign(1, previous_->corners.point(j));
  const RingIndexedCloud::RingQuery query(q);
  for (int r = ring - config_.ring_window; r <= ring + config_.ring_window; ++r) {
    if (r == ring) continue;
    const int k = previous_->corners.nearestInRing(r, query, max_sq, -1);
    if (k >= 0) pts.push_back(previous_->corners.point(k));
  }
  if (static_cast<int>(pts.size()) < std::max(2, config_.line_min_rings)) return std::nullopt;
  // A-LOAM's two-point line (the nearest and the closest other-ring point), unless more rings see the edge and
  // the line is to run through them all (line_through_all_rings).
  if (config_.line_min_rings <= 2 && (pts.size() < 3 || !config_.line_through_all_rings)) {
    std::size_t best = 1;
    for (std::size_t i = 2; i < pts.size(); ++i)
      if ((pts[i] - q).squaredNorm() < (pts[best] - q).squaredNorm()) best = i;
    const Eigen::Vector3d d = pts[best] - pts[0];
    if (d.norm() < 1e-3) return std::nullopt;
    return LineFit{pts[0], d.normalized()};
  }
  const auto line = fitLine(pts, config_.line_eigen_ratio);
  if (!line) return std::nullopt;
  for (const Eigen::Vector3d& x : pts) {
    const Eigen::Vector3d d = x - line->centroid;
    if ((d - line->direction * line->direction.dot(d)).norm() > config_.line_max_point_distance_m) return std::nullopt;
  }
  return line;
}

std::optional<PlaneFit> ScanToScanOdometry::threePointPlane(const Eigen::Vector3d& q, double max_sq) const {
  const int j = previous_->surfs.nearest(q, max_sq);
  if (j < 0) return std::nullopt;
  const int ring = previous_->surfs.ring(j);
  const int l = previous_->surfs.nearestInRing(ring, q, max_sq, j);
  const int k = previous_->surfs.nearestInNeighbourRings(ring, config_.ring_window, q, max_sq);
  if (l < 0 || k < 0) return std::nullopt;
  const Eigen::Vector3d a = previous_->surfs.point(j), b = previous_->surfs.point(l), c = previous_->surfs.point(k);
  const Eigen::Vector3d n = (b - a).cross(c - a);
  if (n.norm() < 1e-9) return std::nullopt;
  return PlaneFit{n.normalized(), -n.normalized().dot(a)};
}

std::optional<PlaneFit> ScanToScanOdometry::fitLocalPlane(const Eigen::Vector3d& q, double max_sq) const {
  if (config_.three_point_planes) return threePointPlane(q, max_sq);
  // The nearest previous surface points, plus the nearest few on each neighbouring ring of the closest one:
  // a sparse sweep's nearest points often lie on one ring (collinear, so the plane's tilt about that line
  // would be noise). A-LOAM takes a single point from the neighbouring ring, which near a wall-floor junction
  // is often on the other face; several points per ring and the outlier check of fitPlane reject that.
  // Scratch buffers, reused (this runs on several threads at once: one set per thread).
  thread_local std::vector<int> near, in_ring;
  thread_local std::vector<Eigen::Vector3d> pts;
  previous_->surfs.nearestK(q, config_.plane_neighbours, max_sq, near);
  if (near.empty()) return std::nullopt;
  const int ring = previous_->surfs.ring(near.front());
  const RingIndexedCloud::RingQuery query(q);
  for (int r = ring - config_.ring_window; r <= ring + config_.ring_window; ++r) {
    if (r == ring) continue;
    previous_->surfs.nearestKInRing(r, query, config_.ring_neighbours, max_sq, in_ring);
    for (int i : in_ring)
      if (std::find(near.begin(), near.end(), i) == near.end()) near.push_back(i);
  }
  pts.clear();
  bool several_rings = false;
  for (int i : near) {
    pts.push_back(previous_->surfs.point(i));
    several_rings = several_rings || previous_->surfs.ring(i) != ring;
  }
  if (!several_rings) return std::nullopt;
  auto plane = fitPlane(pts, config_.plane_max_point_distance_m);
  if (plane && config_.plane_through_nearest) plane->offset = -plane->normal.dot(pts.front());
  return plane;
}

Correspondences ScanToScanOdometry::match(const std::vector<LidarPoint>& sharp, const std::vector<LidarPoint>& flat,
                                          const Eigen::Isometry3d& T, MatchReuse* reuse) const {
  awaitPrevious();
  const double max_sq = config_.max_match_distance_m * config_.max_match_distance_m;
  const auto add_line = [&](std::size_t i, std::vector<LineMatch>& lines) {
    if (!sharp[i].p.allFinite()) return;
    const Eigen::Vector3d p = sharp[i].p.cast<double>(), q = T * p;
    const auto search = [&](const Eigen::Vector3d& at) -> std::optional<LineMatch> {
      if (const auto line = fitLocalLine(at, max_sq)) return LineMatch{p, line->centroid, line->direction};
      return std::nullopt;
    };
    addMatch(reuse, i, q, lines, search);
  };
  const auto add_plane = [&](std::size_t i, std::vector<PlaneMatch>& planes) {
    if (!flat[i].p.allFinite()) return;
    const Eigen::Vector3d p = flat[i].p.cast<double>(), q = T * p;
    const auto search = [&](const Eigen::Vector3d& at) -> std::optional<PlaneMatch> {
      if (const auto plane = fitLocalPlane(at, max_sq)) return PlaneMatch{p, plane->normal, plane->offset};
      return std::nullopt;
    };
    addMatch(reuse, i, q, planes, search);
  };
  return matchInChunks(pool_.get(), sharp.size(), flat.size(), add_line, add_plane);
}

ScanToScanOdometry::Refinement ScanToScanOdometry::refine(const SweepPoints& cur, const Eigen::Isometry3d& seed,
                                                         const Eigen::Isometry3d& hold, bool can_hold,
                                                         const RotationPrior* gyro) const {
  RegistrationConfig registration = config_.registration;
  registration.degeneracy_prior = registration.degeneracy_prior && can_hold;
  Refinement out;
  out.pose = seed;
  out.ok = true;
  MatchReuse reuse(cur.sharp.size(), cur.flat.size(), config_.registration.reuse_match_distance_m);
  for (int round = 0; round < std::max(1, config_.outer_iterations); ++round) {
    out.result = registerStep(match(cur.sharp, cur.flat, out.pose, &reuse), out.pose, hold, registration, gyro);
    out.iterations += out.result.iterations;
    if (!(out.ok = out.result.ok)) break;
    const bool converged = hasConverged(out.pose, out.result.pose);
    out.pose = out.result.pose;
    if (converged) break;
  }
  return out;
}

ScanToScanOdometry::Refinement ScanToScanOdometry::searchStart(const SweepPoints& cur, const Eigen::Isometry3d& seed,
                                                               const Eigen::Isometry3d& hold, bool can_hold,
                                                               double gap_s, const RotationPrior* gyro) const {
  const double reach = config_.startup_max_speed_mps * std::max(0.0, gap_s);
  const std::vector<Eigen::Isometry3d> hypotheses = startupHypotheses(seed, reach, config_.startup_search_step_m);
  // Every seed is refined and scored on a screen of the sweep's sharp and flat points (every stride-th).
  const std::size_t stride =
      screenStride(cur.sharp.size() + cur.flat.size(), config_.startup_screen_points);
  SweepPoints thinned;
  if (stride > 1) {
    for (std::size_t i = 0; i < cur.sharp.size(); i += stride) thinned.sharp.push_back(cur.sharp[i]);
    for (std::size_t i = 0; i < cur.flat.size(); i += stride) thinned.flat.push_back(cur.flat[i]);
  }
  const SweepPoints& screen = stride > 1 ? thinned : cur;
  Refinement best;
  best.pose = seed;
  int best_inliers = -1;
  for (std::size_t i = 0; i < hypotheses.size(); ++i) {
    Refinement r = refine(screen, hypotheses[i], hold, can_hold, gyro);
    if (!r.ok) continue;
    const int inliers = inlierCount(match(screen.sharp, screen.flat, r.pose), r.pose, config_.startup_inlier_distance_m);
    r.from_prior = i == 0;
    if (inliers > best_inliers) best = r, best_inliers = inliers;
  }
  // The winner refined on the whole sweep: the prior from itself, exactly as without the search.
  if (stride > 1 && best.ok) {
    const bool from_prior = best.from_prior;
    best = refine(cur, from_prior ? hypotheses.front() : best.pose, hold, can_hold, gyro);
    best.from_prior = from_prior;
  }
  return best;
}

namespace {

// Rotation block of the inverse of the lidar's information plus the gyro prior's (and the motion model's weak
// translation prior, which keeps the inverse defined where the lidar leaves a translation unobserved).
Eigen::Matrix3d fusedRotationCovariance(const Matrix6d& lidar_information, const RotationPrior& gyro,
                                        const RegistrationConfig& c) {
  Matrix6d info = 0.5 * (lidar_information + lidar_information.transpose());
  if (!info.allFinite()) info.setZero();
  info.bottomRightCorner<3, 3>() += rotationPriorInformation(gyro);
  info.topLeftCorner<3, 3>() += Eigen::Matrix3d::Identity() / (c.prior_sigma_translation_m * c.prior_sigma_translation_m);
  const Matrix6d covariance = info.ldlt().solve(Matrix6d::Identity());
  const Eigen::Matrix3d rotation = covariance.bottomRightCorner<3, 3>();
  return rotation.allFinite() ? Eigen::Matrix3d(0.5 * (rotation + rotation.transpose())) : Eigen::Matrix3d::Zero();
}

}  // namespace

bool ScanToScanOdometry::keepsReference(const Eigen::Isometry3d& T_ref_curr) const {
  return config_.keep_reference_within_m > 0.0 && config_.keep_reference_within_rad > 0.0 &&
         T_ref_curr.translation().norm() < config_.keep_reference_within_m &&
         rotationAngle(T_ref_curr) < config_.keep_reference_within_rad;
}

void ScanToScanOdometry::setPrevious(const SweepPoints& points, bool in_background) {
  prev_points_ = points;
  building_previous_ = {};  // a build still running finishes on its thread, unused
  const auto build = [](const std::vector<LidarPoint>& less_sharp, const std::vector<LidarPoint>& less_flat) {
    return std::shared_ptr<const PreviousIndex>(
        new PreviousIndex{RingIndexedCloud(less_sharp), RingIndexedCloud(less_flat)});
  };
  if (in_background && index_builder_) {
    // The job owns copies of the points and its promise: nothing of this object is touched on the builder.
    auto done = std::make_shared<std::promise<std::shared_ptr<const PreviousIndex>>>();
    building_previous_ = done->get_future().share();
    index_builder_->post([build, done, cpu = background_cpu_, less_sharp = points.less_sharp, less_flat = points.less_flat] {
      const double cpu0 = threadCpuMs();
      try {
        done->set_value(build(less_sharp, less_flat));
      } catch (...) {
        done->set_exception(std::current_exception());
      }
      cpu->add(threadCpuMs() - cpu0);
    });
  } else {
    previous_ = build(points.less_sharp, points.less_flat);
  }
}

double ScanToScanOdometry::helperCpuMs() const {
  if (!pool_) return -1.0;
  return pool_->workerCpuMs() + background_cpu_->ms();
}

void ScanToScanOdometry::awaitPrevious() const {
  if (!building_previous_.valid()) return;
  previous_ = building_previous_.get();
  building_previous_ = {};
}

PoseEstimate ScanToScanOdometry::process(const FeatureSet& f, const std::optional<Eigen::Isometry3d>& prior,
                                         int prior_flags, const std::optional<MeasuredMotion>& measured,
                                         const std::optional<RotationPrior>& weighed_gyro) {
  PoseEstimate out;
  std::optional<RotationPrior> gyro =
      weighed_gyro && weighed_gyro->R.allFinite() && weighed_gyro->sigma_rad > 0.0 ? weighed_gyro : std::nullopt;
  out.utime = f.utime;
  const Eigen::Isometry3d motion_model = predictMotion(f.utime);
  Eigen::Isometry3d seed = motion_model;
  const bool prior_usable = prior && isFinitePose(*prior) &&
                            (config_.use_link3d_seed || (prior_flags & PoseEstimate::kSeededByLinK3d) == 0);
  if (prior_usable) {
    seed = *prior;
    out.flags |= prior_flags & kSeedFlags;
  } else {
    out.flags |= PoseEstimate::kSeededByMotionModel;
  }
  // Along degenerate directions hold to the motion model (with the IMU's rotation if the prior came from the
  // IMU), never to a LinK3D seed: that one is measured from the same, degenerate, geometry.
  const bool imu_prior = prior_usable && (prior_flags & PoseEstimate::kSeededByImu) != 0;
  // A measured motion (wheel odometry) observes what the lidar cannot: hold to it first.
  const bool held_to_measured = measured && isFinitePose(measured->T_prev_curr);
  // With an IMU the degenerate translation holds the same averaged velocity as without one (the IMU's
  // translation is the last step, as noisy as the sweep it came from), until there is none: then the prior's.
  Eigen::Isometry3d hold = held_to_measured                     ? measured->T_prev_curr
                           : imu_prior && !hasVelocity(f.utime) ? *prior
                                                                : predictHeldMotion(f.utime);
  if (!held_to_measured && imu_prior) hold.linear() = prior->linear();
  // A weighed gyro is what a degenerate rotation (the roll of a round roadway) holds to.
  if (gyro) hold.linear() = gyro->R;
  // All of the above is over the interval prev -> curr; the registration's target is the reference sweep
  // (the previous one, or an earlier one kept while the robot barely moves: keep_reference_within_*). The
  // gyro's step is added to the estimated T_ref_prev, not integrated since the reference: its bias error
  // then never adds up, and the weighing acts as a complementary filter of gyro and lidar.
  // The step's prior is then as uncertain as that estimate plus the step (a Kalman prediction): were it held
  // to the step's sigma alone, the lidar could correct the gyro's bias error only at the rate of the ratio of
  // the two informations, and an idling robot's roll and pitch walked 0.6 deg in a minute.
  if (reference_kept_) {
    seed = ref_T_prev_ * seed;
    hold = ref_T_prev_ * hold;
    if (gyro) {
      gyro->R = ref_T_prev_.linear() * gyro->R;
      gyro->covariance = ref_R_prev_covariance_;
    }
  }
  // Before a velocity is known the motion model says nothing (its identity is not "standing still"):
  // holding a degenerate direction to it would pin the estimate at zero motion.
  const bool can_hold = held_to_measured || imu_prior || hasVelocity(f.utime);

  SweepPoints cur{f.corner_sharp, f.surf_flat, f.corner_less_sharp, f.surf_less_flat};
  const bool cur_raw = !f.cloud.deskewed;
  const double gap_s = toSeconds(f.utime - previous_utime_);
  // Exactly one side deskewed: compensate the raw side with the motion estimate, register, and repeat once
  // with the refined motion (the seed may be poor exactly when this happens: at start-up).
  const bool mixed = has_previous_ && config_.compensate_mixed_deskew && cur_raw != previous_raw_;
  const SweepPoints raw_side = mixed ? (cur_raw ? cur : prev_points_) : SweepPoints{};
  Refinement r;
  r.pose = seed;
  // No motion history: the vehicle may already move fast; search along the forward axis. Where the prior
  // wins (e.g. at rest) its refinement is the result, exactly as without the search; another winner started
  // farther from the truth and is refined once more below (measured on kitti_mini 02: APE 0.033 -> 0.024 m).
  bool refined = false;
  if (has_previous_ && !hasVelocity(f.utime) && config_.startup_max_speed_mps > 0.0) {
    r = searchStart(cur, seed, hold, can_hold, gap_s, gyro ? &*gyro : nullptr);
    refined = r.ok && r.from_prior && !mixed;
    if (!r.ok) r.pose = seed;
  }
  for (int pass = 0; has_previous_ && !refined && pass < (mixed ? 2 : 1); ++pass) {
    if (mixed) {
      SweepPoints fixed = raw_side;
      // The velocity over the last interval moves the raw side, whichever sweep the reference is.
      const Eigen::Isometry3d step = reference_kept_ ? ref_T_prev_.inverse() * r.pose : r.pose;
      for (auto* v : {&fixed.sharp, &fixed.flat, &fixed.less_sharp, &fixed.less_flat}) compensateMotion(*v, step, gap_s);
      if (cur_raw) cur = fixed; else setPrevious(fixed);
    }
    const int iterations = r.iterations;
    r = refine(cur, r.pose, hold, can_hold, gyro ? &*gyro : nullptr);
    r.iterations += iterations;
    if (!r.ok) break;
  }
  out.iterations = r.iterations;
  Eigen::Isometry3d T = r.pose;
  Eigen::Matrix3d rotation_covariance = Eigen::Matrix3d::Zero();  // of T_ref_curr's rotation, lidar and gyro
  const bool registered = has_previous_ && r.ok;
  if (registered) {
    RegistrationConfig reported = config_.registration;
    if (held_to_measured) reported.prior_sigma_translation_m = measured->sigma_translation_m;
    reportRegistration(r.result, reported, out);
    rotation_covariance = gyro ? fusedRotationCovariance(r.result.information, *gyro, reported)
                               : Eigen::Matrix3d(out.covariance.bottomRightCorner<3, 3>());
    weakest_translation_ = r.result.degeneracy.translation_directions.col(0);
    if (held_to_measured && (r.result.degeneracy.flags & PoseEstimate::kDegenerateTranslation))
      out.flags |= kPoseHeldToWheel;
  } else {
    T = seed;
    out.covariance = priorCovariance(config_.registration);
    // The very first sweep has nothing to register against: that is not a failure.
    if (has_previous_) out.flags |= PoseEstimate::kRegistrationFailed;
  }

  if (has_previous_) {  // T is T_ref_curr
    const Eigen::Isometry3d step = reference_kept_ ? ref_T_prev_.inverse() * T : T;
    updateHeldVelocity(step, f.utime - previous_utime_, r.ok ? &r.result.information : nullptr);
    last_motion_ = step;
    last_gap_us_ = f.utime - previous_utime_;
    pose_ = reference_pose_ * T;
  }
  out.pose = pose_;
  if (registered) {
    out.pose = standstill_.update(f.utime, pose_);
    if (standstill_.holding()) out.flags |= PoseEstimate::kStandingStill;
  } else {
    standstill_.reset();
  }
  // A compensated raw sweep counts as deskewed from now on (a reference kept after its compensation too).
  reference_kept_ = registered && keepsReference(T);
  if (reference_kept_) {
    ref_T_prev_ = T;
    ref_R_prev_covariance_ = rotation_covariance;
    previous_raw_ = previous_raw_ && !mixed;
  } else {
    ref_R_prev_covariance_.setZero();
    setPrevious(cur, true);
    previous_raw_ = cur_raw && !mixed;
    ref_T_prev_ = Eigen::Isometry3d::Identity();
    reference_pose_ = pose_;
  }
  has_previous_ = true;
  previous_utime_ = f.utime;
  return out;
}

}  // namespace adit
