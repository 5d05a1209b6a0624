#include "loop/loop_closer.hpp"

#include "loop/loop_job.hpp"

#include "core/geometry.hpp"
#include "loop/voxel_filter.hpp"

#include <Eigen/Eigenvalues>

#include <algorithm>
#include <cmath>
#include <limits>

namespace adit {
namespace {

constexpr double kDegToRad = 3.14159265358979323846 / 180.0;

// PoseEstimate's default covariance is identity: a mapper that did not estimate one leaves it so.
bool isUnsetCovariance(const Matrix6d& c) { return c == Matrix6d::Identity(); }

}  // namespace

Matrix6d odometryDriftCovariance(const LoopCloserConfig& c, double metres) {
  const double vt = c.odometry_translation_sigma * c.odometry_translation_sigma * metres +
                    c.odometry_min_translation_sigma * c.odometry_min_translation_sigma;
  const double vr = c.odometry_rotation_sigma * c.odometry_rotation_sigma * metres +
                    c.odometry_min_rotation_sigma * c.odometry_min_rotation_sigma;
  Matrix6d m = Matrix6d::Zero();
  m.diagonal() << vt, vt, vt, vr, vr, vr;
  return m;
}

Matrix6d loopMeasurementCovariance(const LoopCloserConfig& c) {
  const double vt = c.loop_translation_sigma * c.loop_translation_sigma;
  const double vr = c.loop_rotation_sigma * c.loop_rotation_sigma;
  Matrix6d m = Matrix6d::Zero();
  m.diagonal() << vt, vt, vt, vr, vr, vr;
  return m;
}

Matrix6d partialLoopCovariance(const LoopCloserConfig& c, const Eigen::Vector3d& axis) {
  Matrix6d m = loopMeasurementCovariance(c);
  m.topLeftCorner<3, 3>() += c.partial_loop_axis_sigma * c.partial_loop_axis_sigma * axis * axis.transpose();
  return m;
}

namespace {
constexpr double kMeasuredInformation = 1.0;  // 1 / (1 m)^2
}

bool isPartialLoop(const LoopConstraint& loop) {
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig(loop.information.topLeftCorner<3, 3>());
  return eig.eigenvalues()[0] < kMeasuredInformation;
}

Eigen::Vector3d measuredPart(const LoopConstraint& loop, const Eigen::Vector3d& translation) {
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig(loop.information.topLeftCorner<3, 3>());
  Eigen::Vector3d out = Eigen::Vector3d::Zero();
  for (int i = 0; i < 3; ++i)
    if (eig.eigenvalues()[i] >= kMeasuredInformation)
      out += eig.eigenvectors().col(i) * eig.eigenvectors().col(i).dot(translation);
  return out;
}

LoopCloser::LoopCloser(const LoopCloserConfig& config)
    : config_(config), database_(config.candidates, 50) {}
LoopCloser::~LoopCloser() = default;
LoopCloser::LoopCloser(LoopCloser&&) noexcept = default;
LoopCloser& LoopCloser::operator=(LoopCloser&&) noexcept = default;

LoopScheduler& LoopCloser::scheduler() {
  if (!scheduler_) scheduler_ = std::make_unique<LoopScheduler>(config_, LoopBook{accepted_, pending_, last_loop_query_});
  return *scheduler_;
}

std::size_t LoopCloser::jobsInFlight() const { return scheduler_ ? scheduler_->inFlight() : 0; }
double LoopCloser::waitedMs() const { return scheduler_ ? scheduler_->waitedMs() : 0.0; }
double LoopCloser::workerCpuMs() const { return scheduler_ ? scheduler_->workerCpuMs() : 0.0; }

LoopCloser::Result LoopCloser::process(const PoseEstimate& mapped, const LidarScan& cloud,
                                       KeyframeKeypointsPtr keypoints) {
  Result result;
  ++stats_.sweeps;
  const bool out_of_order = !keyframes_.empty() && mapped.utime <= keyframes_.back().utime;
  if (!mapped.pose.matrix().allFinite() || out_of_order) {
    ++stats_.invalid_sweeps;
  } else {
    if (config_.use_mapper_covariance && isValidCovariance(mapped.covariance) && !isUnsetCovariance(mapped.covariance))
      sweeps_since_keyframe_.emplace_back(mapped.pose, mapped.covariance);
    if (isKeyframe(mapped.pose)) {
      const ScanContext context = addKeyframe(mapped, cloud, std::move(keypoints));
      const int k = static_cast<int>(keyframes_.size()) - 1;
      const bool revisit = isRevisit(k);
      // Empty contexts never match: a revisit keyframe is not a place later queries can find.
      database_.add(revisit ? ScanContext() : context, mapped.utime);
      result.keyframe_added = true;
      submitJob(k, context);  // the job keeps its own copy of the cloud and keypoints
      if (revisit) {
        clouds_.drop(k);
        ++stats_.revisit_keyframes;
      }
    }
    applyDue(mapped.utime, false, result);
    if (result.keyframe_added) retireRevisits(result);
  }
  if (!keyframes_.empty()) result.T_corrected_uncorrected = correction(static_cast<int>(keyframes_.size()) - 1);
  return result;
}

LoopCloser::Result LoopCloser::finish() {
  Result result;
  applyDue(0, true, result);
  if (!keyframes_.empty()) result.T_corrected_uncorrected = correction(static_cast<int>(keyframes_.size()) - 1);
  return result;
}

// A snapshot of what verifying the query's candidates needs, posted as a job (loop/loop_job.hpp).
void LoopCloser::submitJob(int query, const ScanContext& context) {
  if (query - last_loop_query_ < config_.cooldown_keyframes) return;  // the job's book can only be later
  if (context.empty()) return;
  const Keyframe& q = keyframes_[static_cast<std::size_t>(query)];
  const std::int64_t latest = q.utime - static_cast<std::int64_t>(config_.exclude_recent_seconds * 1e6);
  LoopJob job;
  for (const ScanContextCandidate& c : database_.query(context, config_.exclude_recent_keyframes, latest)) {
    if (c.distance > config_.max_scan_context_distance ||
        static_cast<int>(job.candidates.size()) >= config_.max_verifications)
      break;
    // Neighbours of the candidate, each at its own current pose; never the query's own recent keyframes.
    LoopCandidateSnapshot snap;
    snap.candidate = c;
    const int m = c.index;
    snap.match_utime = keyframes_[static_cast<std::size_t>(m)].utime;
    snap.match_uncorrected = keyframes_[static_cast<std::size_t>(m)].uncorrected;
    const int newest_allowed = query - std::max(1, config_.exclude_recent_keyframes / 2);
    const Eigen::Isometry3d T_m_world = graph_.pose(m).inverse();
    for (int j = std::max(0, m - config_.verifier.submap_neighbors);
         j <= std::min(newest_allowed, m + config_.verifier.submap_neighbors); ++j) {
      snap.neighbourhood.clouds.push_back(clouds_.cloud(j));
      snap.neighbourhood.T_match_cloud.push_back(T_m_world * graph_.pose(j));
      if (config_.keypoints.use) snap.neighbourhood_keypoints.push_back(clouds_.keypoints(j));
    }
    job.candidates.push_back(std::move(snap));
  }
  if (job.candidates.empty()) {
    ++stats_.queries;  // searched, nothing to verify: no job
    return;
  }
  job.query = query;
  job.query_utime = q.utime;
  job.query_uncorrected = q.uncorrected;
  job.query_cloud = clouds_.cloud(query);
  if (config_.keypoints.use) job.query_keypoints = clouds_.keypoints(query);
  job.graph = graph_;
  job.chain = chain_;
  job.applied_loops = accepted_.size();
  const auto delay_us = static_cast<std::int64_t>(std::max(0.0, config_.apply_delay_s) * 1e6);
  scheduler().submit(std::move(job), q.utime + delay_us);
}

// Applies the outcomes due at `utime` in the order their jobs were posted: loop edges join the graph, and an
// optimised graph replaces the poses of the nodes it held while later keyframes move with the newest of them.
void LoopCloser::applyDue(std::int64_t utime, bool all, Result& result) {
  if (!scheduler_) return;
  for (LoopJobOutcome& o : scheduler_->take(utime, all)) {
    const LoopCloserStats& c = o.counts;
    stats_.queries += c.queries;
    stats_.candidates += c.candidates;
    stats_.rejected_fitness += c.rejected_fitness;
    stats_.rejected_degenerate += c.rejected_degenerate;
    stats_.rejected_odometry += c.rejected_odometry;
    stats_.rejected_pairwise += c.rejected_pairwise;
    stats_.contested += c.contested;
    stats_.accepted += c.accepted;
    stats_.partial_loops += c.partial_loops;
    stats_.keypoint_seeds += c.keypoint_seeds;
    stats_.keypoint_loops += c.keypoint_loops;
    stats_.submaps_reused += c.submaps_reused;
    stats_.rejected_ambiguous += c.rejected_ambiguous;
    stats_.optimizations += c.optimizations;
    stats_.pending = c.pending;
    accepted_ = std::move(o.book.accepted);
    pending_ = std::move(o.book.pending);
    last_loop_query_ = o.book.last_loop_query;
    for (const LoopConstraint& loop : o.loops) {
      graph_.addLoopEdge(loop.match_index, loop.query_index, loop.T_match_query, loop.information);
      result.loops.push_back(loop);
    }
    if (!o.optimized || o.poses.empty()) continue;
    const int held = static_cast<int>(o.poses.size());
    // Re-orthonormalised: Isometry3d::inverse() transposes, so a rotation a rounding error off orthonormal
    // passes its scale on through `moved` to every newer node, and the next job's `moved` doubles it. Over a
    // 30-minute run (hundreds of jobs) POSE_GRAPH quaternions reached norm 1.2 and the mapper refused them.
    const Eigen::Isometry3d moved = orthonormal(o.poses.back() * orthonormal(graph_.pose(held - 1)).inverse());
    for (int k = 0; k < held; ++k) graph_.setPose(k, o.poses[static_cast<std::size_t>(k)]);
    for (int k = held; k < graph_.size(); ++k) graph_.setPose(k, orthonormal(moved * graph_.pose(k)));
    result.graph_updated = true;
  }
  if (!result.loops.empty()) result.loop = result.loops.back();
  if (result.graph_updated) {
    result.corrected_keyframes.clear();
    for (std::size_t k = 0; k < keyframes_.size(); ++k)
      result.corrected_keyframes.push_back({keyframes_[k].utime, graph_.pose(static_cast<int>(k))});
  }
}

bool LoopCloser::isKeyframe(const Eigen::Isometry3d& pose) const {
  if (keyframes_.empty()) return true;
  const Eigen::Isometry3d delta = keyframes_.back().uncorrected.inverse() * pose;
  return translationNorm(delta) >= config_.keyframe_distance ||
         rotationAngle(delta) >= config_.keyframe_angle_deg * kDegToRad;
}

Matrix6d LoopCloser::stepCovariance(const Eigen::Isometry3d& new_pose) const {
  const double d = translationNorm(keyframes_.back().uncorrected.inverse() * new_pose);
  Matrix6d sigma = odometryDriftCovariance(config_, d);
  const Eigen::Isometry3d T_new_world = new_pose.inverse();
  for (const auto& [pose, covariance] : sweeps_since_keyframe_) {
    const Matrix6d A = adjoint(T_new_world * pose);
    sigma += A * covariance * A.transpose();
  }
  return sigma;
}

// A place already mapped by an older keyframe that keeps its cloud, reached by a trajectory that a recent loop
// ties to that older map (without the loop, drift could put an unmapped place near an old keyframe).
bool LoopCloser::isRevisit(int keyframe) const {
  if (config_.revisit_distance <= 0 || accepted_.empty() ||
      accepted_.back().query_index < keyframe - config_.revisit_trust_keyframes)
    return false;
  const Eigen::Vector3d here = graph_.pose(keyframe).translation();
  const int older_than = keyframe - config_.exclude_recent_keyframes;
  for (int j = 0; j < older_than; ++j) {
    if (!clouds_.empty(j) &&
        (graph_.pose(j).translation() - here).norm() < config_.revisit_distance)
      return true;
  }
  return false;
}

// Adds the keyframe's cloud and graph node; returns its Scan Context (the caller adds it to the database).
ScanContext LoopCloser::addKeyframe(const PoseEstimate& mapped, const LidarScan& cloud,
                                    KeyframeKeypointsPtr keypoints) {
  std::vector<Eigen::Vector3f> points;
  points.reserve(cloud.points.size());
  for (const LidarPoint& p : cloud.points)
    if (p.p.allFinite()) points.push_back(p.p);

  Keyframe kf;
  kf.utime = mapped.utime;
  kf.uncorrected = mapped.pose;
  kf.seq = stats_.keyframes;

  if (keyframes_.empty()) {
    chain_.add(mapped.pose, Matrix6d::Zero());
    graph_.addNode(mapped.pose);
  } else {
    const int prev = static_cast<int>(keyframes_.size()) - 1;
    const Eigen::Isometry3d step = keyframes_.back().uncorrected.inverse() * mapped.pose;
    const Matrix6d covariance = stepCovariance(mapped.pose);
    chain_.add(mapped.pose, covariance);
    const int id = graph_.addNode(graph_.pose(prev) * step);
    graph_.addOdometryEdge(prev, id, step, covariance.inverse());
  }
  sweeps_since_keyframe_.clear();
  keyframes_.push_back(std::move(kf));
  if (!config_.keypoints.use) keypoints.reset();
  clouds_.add(CompactCloud::encode(voxelDownsample(points, config_.keyframe_voxel),
                                   static_cast<float>(config_.keyframe_cloud_step)),
              std::move(keypoints));
  ++stats_.keyframes;
  return keyframeScanContext(std::move(points), mapped.pose, config_.level_scan_context, config_.scan_context);
}

KeyframeKeypoints LoopCloser::keyframeKeypoints(int k) const {
  const KeyframeKeypointsPtr p = clouds_.keypoints(k);
  return p ? *p : KeyframeKeypoints();
}

void LoopCloser::pageKeyframesTo(const std::string& path, std::size_t resident) {
  clouds_.pageTo(path, resident);
  database_.pageTo(path + ".sc", resident);
}

Eigen::Isometry3d LoopCloser::correction(int keyframe) const {
  return graph_.pose(keyframe) * keyframes_[static_cast<std::size_t>(keyframe)].uncorrected.inverse();
}

int LoopCloser::indexOfKeyframe(std::int64_t seq) const {
  const auto it = std::lower_bound(keyframes_.begin(), keyframes_.end(), seq,
                                   [](const Keyframe& k, std::int64_t s) { return k.seq < s; });
  return it != keyframes_.end() && it->seq == seq ? static_cast<int>(it - keyframes_.begin()) : -1;
}

Trajectory LoopCloser::correctedTrajectory(const Trajectory& uncorrected) const {
  if (keyframes_.empty()) return uncorrected;
  // Every keyframe's correction in time order: the graph's, and those merged out as they were then.
  std::vector<std::int64_t> utimes;
  std::vector<Eigen::Isometry3d> corrections;
  std::size_t r = 0;
  for (std::size_t k = 0; k <= keyframes_.size(); ++k) {
    const std::int64_t next = k < keyframes_.size() ? keyframes_[k].utime : std::numeric_limits<std::int64_t>::max();
    for (; r < retired_.size() && retired_[r].utime < next; ++r) {
      const RetiredKeyframe& x = retired_[r];
      const int anchor = indexOfKeyframe(x.anchor_seq);  // always in the graph (re-anchored when merged out)
      utimes.push_back(x.utime);
      corrections.push_back(anchor >= 0 ? correction(anchor) * x.offset() : x.offset());
    }
    if (k == keyframes_.size()) break;
    utimes.push_back(keyframes_[k].utime);
    corrections.push_back(correction(static_cast<int>(k)));
  }
  const int n = static_cast<int>(utimes.size());
  Trajectory out;
  out.reserve(uncorrected.size());
  for (const StampedPose& sp : uncorrected) {
    const int b = static_cast<int>(std::upper_bound(utimes.begin(), utimes.end(), sp.utime) - utimes.begin());
    Eigen::Isometry3d C;
    if (b == 0) {
      C = corrections.front();
    } else if (b == n) {
      C = corrections.back();
    } else {
      const auto i = static_cast<std::size_t>(b);
      const double span = static_cast<double>(utimes[i] - utimes[i - 1]);
      const double s = span > 0 ? static_cast<double>(sp.utime - utimes[i - 1]) / span : 0.0;
      C = interpolate(corrections[i - 1], corrections[i], s);
    }
    out.push_back({sp.utime, C * sp.pose});
  }
  return out;
}

std::vector<Eigen::Vector3f> LoopCloser::correctedMap(double voxel) const {
  // Keyframe by keyframe into the grid: a 30-minute run's keyframes hold ~10^7 points, far more than its map.
  std::vector<Eigen::Vector3f> points;
  std::optional<VoxelAccumulator> grid;
  if (voxel > 0) grid.emplace(voxel);
  for (std::size_t k = 0; k < keyframes_.size(); ++k) {
    if (clouds_.empty(static_cast<int>(k))) continue;  // a revisit: its place is in an older keyframe's cloud
    const Eigen::Isometry3f T = graph_.pose(static_cast<int>(k)).cast<float>();
    std::vector<Eigen::Vector3f> placed = clouds_.cloud(static_cast<int>(k)).decode();
    for (Eigen::Vector3f& p : placed) p = T * p;
    if (grid) {
      grid->add(placed);
    } else {
      for (const Eigen::Vector3f& w : placed)
        if (w.allFinite()) points.push_back(w);
    }
  }
  return grid ? grid->centroids() : points;
}

}  // namespace adit
