// Scan-to-scan lidar odometry (A-LOAM laserOdometry, with the known defects fixed): registers each sweep's
// sharp edges and flat surfaces against the previous sweep's less-sharp / less-flat points, point-to-line and
// point-to-plane with the registration core (lib/registration), correspondences recomputed every outer
// round, degeneracy measured from the information matrix and held to the motion model. Deterministic: the
// output depends only on the inputs and config.
#pragma once

#include "core/config_table.hpp"
#include "core/serial_worker.hpp"
#include "core/thread_cpu.hpp"
#include "core/types.hpp"
#include "registration/feature_fit.hpp"
#include "registration/pose_increment.hpp"
#include "registration/solver.hpp"
#include "odometry/ring_cloud.hpp"
#include "odometry/standstill.hpp"

#include <future>
#include <memory>
#include <optional>

namespace adit {

class MatchReuse;  // registration/match_reuse.hpp

class ChunkPool;  // core/chunk_pool.hpp

struct ScanToScanConfig {
  RegistrationConfig registration;  // keys "odometry.<field>" (see registration.hpp)
  // Correspondence rounds; correspondences are recomputed at the new pose each round. A-LOAM uses 2.
  int outer_iterations = 3;
  // Largest point-to-neighbour distance accepted when matching (m). Generous because the first sweeps of a
  // run have no velocity estimate yet (KITTI moves up to 1.5 m per sweep); A-LOAM uses 5 m.
  double max_match_distance_m = 3.0;
  // Rings either side searched for the second line point / third plane point (A-LOAM: 2.5 -> 2).
  int ring_window = 2;
  // Edge lines: the nearest previous less-sharp point and the nearest on each ring within ring_window; at
  // least line_min_rings such points (one per ring) must be collinear: PCA ratio above line_eigen_ratio and
  // none farther than line_max_point_distance_m from the line. 2 is A-LOAM's two-point line (nearest point
  // and nearest on another ring). Measured: 3 is no better on simulated roadways (odometry end error over
  // 20 m within +-0.2 m either way) and worse on kitti_mini (worst pair 0.21-0.23 deg against 0.16-0.20).
  int line_min_rings = 2;
  // Where three or more rings see the edge (the nearest point on each within ring_window), the line is fitted
  // to all of them and must pass the checks above, instead of A-LOAM's line through the nearest point and the
  // closest point on another ring; an edge only two rings see keeps that two-point line. On a 16-beam lidar a
  // two-point line is often a chord of a curved edge (an arch rib, a rock crest: 17 cm between rings at 5 m),
  // and a point matched to a chord is pulled off its edge: the estimate climbed 3-5 mm a sweep. Measured
  // (roadway-loop 120 s, seeds 1-3, with the reference kept at rest and the gyro's bias fitted), scan-to-scan
  // end-point drift: two-point lines 2.03 / 3.25 / 3.69 %, this 2.40 / 1.41 / 1.82 % (mean 2.99 -> 1.88 %);
  // the mapped APE 0.0642 -> 0.0650 m on seed 1 and its map against the world 0.0234 -> 0.0223 m mean;
  // kitti_mini 00 / 01 / 02 0.3107 / 0.0356 / 0.0249 -> 0.3115 / 0.0345 / 0.0211 m; the 12 s demo's map
  // 0.020 -> 0.026 m mean (session 15 found that and kept it off). line_min_rings 3 (no two-point lines at
  // all) put a 10 s lidar stall's motion 0.47 m off.
  bool line_through_all_rings = true;
  double line_eigen_ratio = 3.0;
  double line_max_point_distance_m = 0.1;
  // Planes are fitted (least squares) to the plane_neighbours nearest previous less-flat points plus the
  // ring_neighbours nearest on each ring within ring_window of the closest one, and rejected if any of them
  // is farther than plane_max_point_distance_m from the plane (A-LOAM mapping uses 0.2 m; tighter here
  // because a plane straddling a wall-floor junction must be caught: with 0.2 m, 2% of corridor planes were
  // tilted by such straddles).
  int plane_neighbours = 5;
  int ring_neighbours = 3;
  double plane_max_point_distance_m = 0.1;
  // The fitted plane is moved to pass through the nearest previous point instead of the neighbours' centroid
  // (as mapping.plane_through_nearest). With features.loam.less_flat_measured, a flat point of a sweep that
  // did not move finds itself: exact zero motion at rest with exact sensors. Off: with range noise the nearest
  // point's own noise enters every plane (roadway-loop 120 s, scan-to-scan drift 3.5 % -> 7.7 %; issue 16).
  bool plane_through_nearest = false;
  // A-LOAM's plane instead: through the nearest point, its nearest on the same ring and the nearest on a
  // neighbouring ring, unchecked (ablation only).
  bool three_point_planes = false;
  // Accept a prior flagged kSeededByLinK3d as initial guess (false = A-LOAM ablation: motion model only).
  bool use_link3d_seed = true;
  // When exactly one of two consecutive sweeps arrives deskewed (start-up: the feature stage has no motion
  // prior for the first sweeps), move the raw one's points to its end instant with the estimated motion
  // (motion_compensation.hpp). Without this, KITTI's first deskewed pair errs by ~0.6 m.
  bool compensate_mixed_deskew = true;
  // Longest gap between sweeps (s) over which the last motion is extrapolated; across a longer gap (lost
  // sweeps, a stalled sensor) the averaged velocity is (hold_velocity_time_constant_s): one sweep's motion
  // scaled over many sweeps would amplify its noise, and no motion at all would lose track of a moving robot.
  double max_velocity_gap_s = 0.5;
  // Time constant (s) of the velocity that degenerate directions are held to: an exponential average of the
  // estimated motions rather than the last one. Where the roadway axis is barely observed (just before it is
  // flagged degenerate) a single sweep's axial motion errs by ~3 cm (20% at 1.3 m/s), and the prior then
  // carries whatever the last sweep said along the whole degenerate stretch. A robot's speed changes slowly
  // (0.3 m/s^2 is 3 cm/s a sweep), so averaging over ~1 s costs little lag. 0 = the last motion. With an
  // IMU too: its seed's translation is the last step (held, it made the 320 m featureless world 10.5 % long
  // instead of 3.0 %); only its rotation is taken.
  double hold_velocity_time_constant_s = 1.0;
  // That average weighs each sweep's velocity along each translation eigen-direction of the registration's
  // information (every residual, edges too) by how well it was observed: not at all below
  // degeneracy_ratio_translation times the largest eigenvalue, fully from hold_velocity_observed_ratio times
  // the largest on, linearly between. As a featureless roadway's axis fades from view its registration is
  // pulled toward zero motion (points on smooth walls slide with the sensor) before it is flagged degenerate;
  // unweighted, those sweeps dragged the held velocity low (featureless 60 s without IMU, range 30 m:
  // end-point 11.6 % -> 10.9 %; 9.5 % with 0.2, which cost roadway-loop 120 s 0.6 % of its APE: a few of
  // its sweeps fall below 0.2). Structured roadways observe their axis at 0.22-0.36 of the largest
  // eigenvalue with all residuals: unaffected. 0 = every direction fully (the unweighted average).
  double hold_velocity_observed_ratio = 0.1;
  // Standard deviation (rad, per axis, per sweep) of the bias-corrected gyro's rotation over a sweep interval
  // (odometry/gyro_bias.hpp), which the registration weighs its rotation against (process()'s gyro): on a
  // noisy 16-beam lidar, scan-to-scan rotation errs by ~0.3 deg a sweep at rest and drifts ~20 deg in two
  // minutes of roadway-loop; an N100-class gyro integrates ~0.003 deg of noise a sweep, and its bias, once
  // measured at a stop, drifts by ~1 deg in those two minutes. 0 = the gyro only seeds the registration.
  double gyro_rotation_sigma_rad = 1e-4;
  // Start-up search (startup_search.hpp): with no motion history (the first pair of a run, after a reset or a
  // restart) the vehicle may already move at any speed up to startup_max_speed_mps. Seeds along the forward
  // axis every startup_search_step_m, up to that speed times the interval, either way, are each refined and
  // the one with the most correspondences within startup_inlier_distance_m is kept. The step is below the
  // registration's reach from a seed (~0.5-1 m along a roadway with the 3 m matching radius). 30 m/s covers a
  // road vehicle; a mine robot needs far less, but the search costs a few ms per seed, once. 0 = off: the
  // first registration starts from the prior or zero motion (A-LOAM).
  double startup_max_speed_mps = 30.0;
  double startup_search_step_m = 0.5;
  double startup_inlier_distance_m = 0.1;
  // The seeds are refined and scored on at least this many of the sweep's sharp and flat points (every k-th,
  // k = points / this), and the winner on all of them: a 64-beam sweep has ~2,300, and refining 14 seeds on
  // all took ~170 ms of one core (200: ~40 ms); a 16-beam sweep's ~580 are halved. The screen keeps the
  // winner (kitti_mini 00-02, the start-speed tests). 0 = all points.
  int startup_screen_points = 200;
  // Reference sweep: a sweep is registered against the last sweep that moved the robot at least
  // keep_reference_within_m or keep_reference_within_rad from the one before it, not always the previous
  // sweep. At rest (or crawling) consecutive registrations each err by a few mm and a few hundredths of a
  // degree (range noise, point selection) and scan-to-scan odometry sums those errors: 1-5 m in a minute
  // standing still (issue 16). Against a kept reference each sweep's error stays that of one registration.
  // Driving at 1.3 m/s (0.13 m a sweep) the reference is the previous sweep, as before. 0 = always the
  // previous sweep (A-LOAM).
  double keep_reference_within_m = 0.1;
  double keep_reference_within_rad = 0.0175;
  // A robot standing still reports the mean position of its registrations against the kept reference
  // (odometry/standstill.hpp; keys odometry.standstill.*); the next sweep still registers from its own. One
  // registration against the reference errs by 6-8 mm per axis on a noisy 16-beam lidar and an idling
  // chassis, twice the mapper's, hence a looser speed bound than the mapper's (at rest the 2 s line's slope
  // stays within ~10 mm/s): docs/measurements.md, "Standing still".
  StandstillConfig standstill = [] {
    StandstillConfig c;
    c.max_speed_mps = 0.02;
    return c;
  }();
};

// Plain A-LOAM laserOdometry behaviour, for the "before vs after" ablation: motion-model seed only (LinK3D
// ignored), no degeneracy prior, A-LOAM's two-point lines and three-point planes, 2 rounds of 4 iterations,
// 5 m matching radius, no compensation of raw sweeps.
ScanToScanConfig aloamOdometryConfig();

// Keys "odometry.*" (the registration's included).
const ConfigTable<ScanToScanConfig>& scanToScanConfigTable();
// Reads "odometry.*" keys with the defaults above. If "ablation.aloam" is true the defaults are those of
// aloamOdometryConfig() (explicit odometry.* keys still override them). Throws ConfigError.
ScanToScanConfig scanToScanConfigFrom(const Config& c);

// The ablation switch "ablation.aloam": plain A-LOAM defaults in odometry and mapping (see aloam.yaml).
struct AblationConfig {
  bool aloam = false;
};
const ConfigTable<AblationConfig>& ablationConfigTable();

// A motion over the sweep interval measured by another sensor (wheel odometry, odometry/wheel_motion.hpp):
// degenerate directions hold to it instead of the averaged velocity, and its translation's 1-sigma is their
// covariance.
struct MeasuredMotion {
  Eigen::Isometry3d T_prev_curr = Eigen::Isometry3d::Identity();
  double sigma_translation_m = 0.1;
};

class ScanToScanOdometry {
 public:
  explicit ScanToScanOdometry(ScanToScanConfig config = {});

  // Registers the sweep against the previous one and returns T_odom_lidar at f.utime. prior_T_prev_curr is
  // an optional initial guess (LinK3D RANSAC, IMU rotation) whose origin is given by prior_flags
  // (PoseEstimate::kSeededByLinK3d / kSeededByImu / kSeededByMotionModel); without it, constant velocity.
  // Never throws: a sweep that cannot be registered keeps the prior motion and is flagged
  // kRegistrationFailed.
  // `measured`: see MeasuredMotion (flagged kPoseHeldToWheel when used).
  // `gyro`: the gyro's rotation R_prev_curr over the interval and its uncertainty, which the registration's
  // rotation is weighed against.
  PoseEstimate process(const FeatureSet& f, const std::optional<Eigen::Isometry3d>& prior_T_prev_curr = std::nullopt,
                       int prior_flags = 0, const std::optional<MeasuredMotion>& measured = std::nullopt,
                       const std::optional<RotationPrior>& gyro = std::nullopt);

  // Constant-velocity guess of T_prev_curr for a sweep at `utime` (identity before two sweeps were seen).
  Eigen::Isometry3d predictMotion(std::int64_t utime) const;
  // Constant-velocity guess from the averaged velocity (hold_velocity_time_constant_s): what degenerate
  // directions are held to.
  Eigen::Isometry3d predictHeldMotion(std::int64_t utime) const;
  // True when predictMotion(utime) is an extrapolated velocity rather than the identity of ignorance.
  bool hasVelocity(std::int64_t utime) const;

  // The correspondences of sharp / flat points against the previous sweep at a guess of T_prev_curr
  // (what one registration round uses; public for diagnostics and tests). With `reuse`, a query that barely
  // moved since an earlier round of the same registration keeps that round's match (match_reuse.hpp).
  Correspondences match(const std::vector<LidarPoint>& sharp, const std::vector<LidarPoint>& flat,
                        const Eigen::Isometry3d& T_prev_curr, MatchReuse* reuse = nullptr) const;

  // T_odom_lidar of the last registration, what the next sweep registers from (the pose process() reported
  // may be held instead: standstill).
  const Eigen::Isometry3d& pose() const { return pose_; }
  const ScanToScanConfig& config() const { return config_; }
  // CPU time (ms, monitoring only) of the search threads beside the caller's and of the previous sweep's
  // index builds in the background: negative without search threads.
  double helperCpuMs() const;
  // The velocity (tangent, per second) of the last step (zero before two sweeps) and the time of the last
  // sweep: what a restart extrapolates (the last step, not the averaged velocity, which lags when the robot
  // speeds up: measured 1.1 m short over a 1.9 s restart gap while accelerating).
  Vector6d lastVelocity() const;
  std::int64_t lastUtime() const { return has_previous_ ? previous_utime_ : -1; }
  // The last registration's least-observed translation direction (lidar frame; its degeneracy analysis),
  // whatever held it: a covariance held to the wheel no longer shows it.
  const Eigen::Vector3d& weakestTranslationDirection() const { return weakest_translation_; }
  // True when the last sweep was registered against an earlier reference sweep kept at rest, not the previous one.
  bool referenceKept() const { return reference_kept_; }
  void reset();
  // Starts over (no previous sweep, no velocity) but at `pose` instead of the identity: after a restart or a
  // gap in the input, the odometry frame continues where it was.
  void resumeAt(const Eigen::Isometry3d& pose);


 private:
  struct SweepPoints {
    std::vector<LidarPoint> sharp, flat, less_sharp, less_flat;
  };
  struct Refinement {
    bool ok = false;
    Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
    RegistrationResult result;  // of the last round
    int iterations = 0;
    bool from_prior = false;    // start-up search: refined from the prior itself
  };
  // The start-up search: the refinement of the seed among startupHypotheses(seed, ...) that explains most of
  // the sweep, for an interval of gap_s (ok false if none could be refined).
  Refinement searchStart(const SweepPoints& cur, const Eigen::Isometry3d& seed, const Eigen::Isometry3d& hold,
                         bool can_hold, double gap_s, const RotationPrior* gyro) const;
  // Outer rounds (correspondences recomputed each) from `seed` until converged or out of rounds.
  Refinement refine(const SweepPoints& cur, const Eigen::Isometry3d& seed, const Eigen::Isometry3d& hold,
                    bool can_hold, const RotationPrior* gyro) const;
  // in_background: build the index on another thread (when search_threads > 1).
  void setPrevious(const SweepPoints& points, bool in_background = false);
  std::optional<LineFit> fitLocalLine(const Eigen::Vector3d& q, double max_sq) const;
  std::optional<PlaneFit> threePointPlane(const Eigen::Vector3d& q, double max_sq) const;
  std::optional<PlaneFit> fitLocalPlane(const Eigen::Vector3d& q, double max_sq) const;

  ScanToScanConfig config_;
  std::shared_ptr<ChunkPool> pool_;  // correspondence search threads (none: search_threads 1)
  // The previous sweep's search index: corner_less_sharp and surf_less_flat, previous lidar frame. With
  // search_threads > 1 it is built on another thread while the rest of the pipeline runs (the same index,
  // off the odometry's critical path) and taken over by the next match (awaitPrevious()).
  struct PreviousIndex {
    RingIndexedCloud corners, surfs;
  };
  void awaitPrevious() const;
  mutable std::shared_ptr<const PreviousIndex> previous_ = std::make_shared<const PreviousIndex>();
  mutable std::shared_future<std::shared_ptr<const PreviousIndex>> building_previous_;
  // The thread those builds run on (with search threads only), and their CPU (shared with a build still
  // running when the odometry is copied or reset).
  std::shared_ptr<SerialWorker> index_builder_;
  std::shared_ptr<CpuTally> background_cpu_ = std::make_shared<CpuTally>();
  SweepPoints prev_points_;        // the previous sweep's features, kept to compensate them if they were raw
  bool previous_raw_ = false;      // the previous sweep was not deskewed
  bool has_previous_ = false;
  std::int64_t previous_utime_ = 0;
  Eigen::Isometry3d pose_ = Eigen::Isometry3d::Identity();        // T_odom_lidar of the previous sweep
  // The reference sweep (what previous_ indexes) as seen from the previous sweep's pose: identity when the
  // reference is the previous sweep, T_ref_prev while a reference is kept (keep_reference_within_*).
  Eigen::Isometry3d ref_T_prev_ = Eigen::Isometry3d::Identity();
  Eigen::Isometry3d reference_pose_ = Eigen::Isometry3d::Identity();  // T_odom_lidar of the reference sweep
  // Covariance of ref_T_prev_'s rotation as estimated (rad^2; zero when the reference is the previous sweep):
  // the gyro's step starts from that estimate, so the step's prior is no surer than it.
  Eigen::Matrix3d ref_R_prev_covariance_ = Eigen::Matrix3d::Zero();
  bool reference_kept_ = false;
  bool keepsReference(const Eigen::Isometry3d& T_ref_curr) const;
  Eigen::Isometry3d last_motion_ = Eigen::Isometry3d::Identity();  // T_prev_curr of the previous step
  std::int64_t last_gap_us_ = 0;                                   // 0: no velocity estimate yet
  Vector6d held_velocity_ = Vector6d::Zero();  // averaged tangent velocity (per second), see predictHeldMotion
  Eigen::Vector3d weakest_translation_ = Eigen::Vector3d::UnitX();
  void updateHeldVelocity(const Eigen::Isometry3d& T_prev_curr, std::int64_t gap_us,
                          const Matrix6d* information = nullptr);
  StandstillHold standstill_;
};

}  // namespace adit
