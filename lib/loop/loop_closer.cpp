#include "loop/loop_closer.hpp"

#include "core/geometry.hpp"
#include "loop/voxel_filter.hpp"

#include <algorithm>
#include <cmath>

namespace adit {
namespace {

constexpr double kDegToRad = 3.14159265358979323846 / 180.0;

// Rotation that removes the heading of a pose but keeps its roll and pitch: levelled = L * lidar.
Eigen::Matrix3d levellingRotation(const Eigen::Isometry3d& T_world_lidar) {
  const Eigen::Matrix3d R = T_world_lidar.linear();
  const double yaw = std::atan2(R(1, 0), R(0, 0));
  return Eigen::AngleAxisd(-yaw, Eigen::Vector3d::UnitZ()).toRotationMatrix() * R;
}

// PoseEstimate's default covariance is identity: a mapper that did not estimate one leaves it so.
bool isUnsetCovariance(const Matrix6d& c) { return c == Matrix6d::Identity(); }

Eigen::Isometry3d rotationOnly(const Eigen::Matrix3d& R) {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = R;
  return T;
}

}  // namespace

LoopCloser::LoopCloser(const LoopCloserConfig& config)
    : config_(config), database_(config.candidates, 50) {}

LoopCloser::Result LoopCloser::process(const PoseEstimate& mapped, const LidarScan& cloud,
                                       const std::vector<Eigen::Vector3f>* /*keypoints*/) {
  Result result;
  ++stats_.sweeps;
  const bool out_of_order = !keyframes_.empty() && mapped.utime <= keyframes_.back().utime;
  if (!mapped.pose.matrix().allFinite() || out_of_order) {
    ++stats_.invalid_sweeps;
    if (!keyframes_.empty()) result.T_corrected_uncorrected = correction(static_cast<int>(keyframes_.size()) - 1);
    return result;
  }
  if (config_.use_mapper_covariance && isValidCovariance(mapped.covariance) && !isUnsetCovariance(mapped.covariance))
    sweeps_since_keyframe_.emplace_back(mapped.pose, mapped.covariance);

  if (isKeyframe(mapped.pose)) {
    addKeyframe(mapped, cloud);
    result.keyframe_added = true;
    const int query = static_cast<int>(keyframes_.size()) - 1;
    result.loops = detectLoops(query);
    if (!result.loops.empty()) {
      for (const LoopConstraint& loop : result.loops)
        graph_.addLoopEdge(loop.match_index, loop.query_index, loop.T_match_query, loop.information);
      graph_.optimize(config_.graph);
      ++stats_.optimizations;
      result.loop = result.loops.back();
      result.graph_updated = true;
      for (std::size_t k = 0; k < keyframes_.size(); ++k)
        result.corrected_keyframes.push_back({keyframes_[k].utime, graph_.pose(static_cast<int>(k))});
    }
  }
  if (!keyframes_.empty()) result.T_corrected_uncorrected = correction(static_cast<int>(keyframes_.size()) - 1);
  return result;
}

bool LoopCloser::isKeyframe(const Eigen::Isometry3d& pose) const {
  if (keyframes_.empty()) return true;
  const Eigen::Isometry3d delta = keyframes_.back().uncorrected.inverse() * pose;
  return translationNorm(delta) >= config_.keyframe_distance ||
         rotationAngle(delta) >= config_.keyframe_angle_deg * kDegToRad;
}

Matrix6d LoopCloser::stepCovariance(const Eigen::Isometry3d& new_pose) const {
  const double d = translationNorm(keyframes_.back().uncorrected.inverse() * new_pose);
  const double var_t = config_.odometry_translation_sigma * config_.odometry_translation_sigma * d +
                       config_.odometry_min_translation_sigma * config_.odometry_min_translation_sigma;
  const double var_r = config_.odometry_rotation_sigma * config_.odometry_rotation_sigma * d +
                       config_.odometry_min_rotation_sigma * config_.odometry_min_rotation_sigma;
  Matrix6d sigma = Matrix6d::Zero();
  sigma.diagonal() << var_t, var_t, var_t, var_r, var_r, var_r;
  const Eigen::Isometry3d T_new_world = new_pose.inverse();
  for (const auto& [pose, covariance] : sweeps_since_keyframe_) {
    const Matrix6d A = adjoint(T_new_world * pose);
    sigma += A * covariance * A.transpose();
  }
  return sigma;
}

void LoopCloser::addKeyframe(const PoseEstimate& mapped, const LidarScan& cloud) {
  std::vector<Eigen::Vector3f> points;
  points.reserve(cloud.points.size());
  for (const LidarPoint& p : cloud.points)
    if (p.p.allFinite()) points.push_back(p.p);

  Keyframe kf;
  kf.utime = mapped.utime;
  kf.uncorrected = mapped.pose;
  kf.cloud = voxelDownsample(points, config_.keyframe_voxel);

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

  if (config_.level_scan_context) {
    const Eigen::Matrix3f L = levellingRotation(mapped.pose).cast<float>();
    for (Eigen::Vector3f& p : points) p = L * p;
  }
  database_.add(ScanContext::build(points, config_.scan_context), kf.utime);
  keyframes_.push_back(std::move(kf));
  ++stats_.keyframes;
}

std::vector<LoopConstraint> LoopCloser::detectLoops(int query) {
  if (query - last_loop_query_ < config_.cooldown_keyframes) return {};
  const ScanContext& context = database_.context(query);
  if (context.empty()) return {};
  ++stats_.queries;
  const std::int64_t latest = keyframes_[static_cast<std::size_t>(query)].utime -
                              static_cast<std::int64_t>(config_.exclude_recent_seconds * 1e6);
  const std::vector<ScanContextCandidate> candidates =
      database_.query(context, config_.exclude_recent_keyframes, latest);
  int verified = 0;
  for (const ScanContextCandidate& c : candidates) {
    if (c.distance > config_.max_scan_context_distance || verified >= config_.max_verifications) break;
    ++stats_.candidates;
    ++verified;
    const std::optional<LoopConstraint> loop = verifyCandidate(query, c);
    if (!loop) continue;
    std::vector<LoopConstraint> accepted = admit(*loop);
    if (!accepted.empty()) {
      last_loop_query_ = query;
      stats_.accepted += static_cast<int>(accepted.size());
      accepted_.insert(accepted_.end(), accepted.begin(), accepted.end());
    }
    return accepted;  // one verified loop per keyframe is enough
  }
  return {};
}

std::optional<LoopConstraint> LoopCloser::verifyCandidate(int query, const ScanContextCandidate& candidate) {
  const int m = candidate.index;
  // Neighbours of the candidate, each at its own current pose; never the query's own recent keyframes.
  const int newest_allowed = query - std::max(1, config_.exclude_recent_keyframes / 2);
  const Eigen::Isometry3d T_m_world = graph_.pose(m).inverse();
  std::vector<SubmapPiece> pieces;
  for (int j = std::max(0, m - config_.verifier.submap_neighbors);
       j <= std::min(newest_allowed, m + config_.verifier.submap_neighbors); ++j)
    pieces.push_back({&keyframes_[static_cast<std::size_t>(j)].cloud, T_m_world * graph_.pose(j)});
  const std::vector<Eigen::Vector3f> submap = buildSubmap(pieces, config_.verifier.submap_voxel);

  // Seeds: the Scan Context yaw at zero offset (levelled frames: query = Rz(yaw) * match), then the graph's
  // current relative pose.
  const Keyframe& q = keyframes_[static_cast<std::size_t>(query)];
  const Keyframe& mk = keyframes_[static_cast<std::size_t>(m)];
  Eigen::Matrix3d L_q = Eigen::Matrix3d::Identity(), L_m = Eigen::Matrix3d::Identity();
  if (config_.level_scan_context) {
    L_q = levellingRotation(q.uncorrected);
    L_m = levellingRotation(mk.uncorrected);
  }
  const Eigen::Matrix3d R_yaw = Eigen::AngleAxisd(-candidate.yaw, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  const Eigen::Isometry3d T_graph = T_m_world * graph_.pose(query);
  const std::vector<Eigen::Isometry3d> seeds{rotationOnly(L_m.transpose() * R_yaw * L_q), T_graph};

  const LoopVerification v = verifyLoop(q.cloud, submap, seeds, config_.verifier);
  if (v.verdict == LoopVerdict::kDegenerate) {
    ++stats_.rejected_degenerate;
    return std::nullopt;
  }
  if (v.verdict != LoopVerdict::kAccepted) {
    ++stats_.rejected_fitness;
    return std::nullopt;
  }
  const Matrix6d loop_cov = loopCovariance();
  const double chi2 = loopChi2(v.T_match_query, T_graph, chain_.covarianceBetween(m, query), loop_cov);
  if (!(chi2 <= config_.max_odometry_chi2)) {
    ++stats_.rejected_odometry;
    return std::nullopt;
  }
  LoopConstraint loop;
  loop.query_index = query;
  loop.match_index = m;
  loop.query_utime = q.utime;
  loop.match_utime = mk.utime;
  loop.T_match_query = v.T_match_query;
  loop.information = loop_cov.inverse();
  loop.scan_context_distance = candidate.distance;
  loop.scan_context_yaw = candidate.yaw;
  loop.fitness = v.icp.rms;
  loop.inlier_ratio = v.icp.inlier_ratio;
  return loop;
}

Matrix6d LoopCloser::loopCovariance() const {
  const double vt = config_.loop_translation_sigma * config_.loop_translation_sigma;
  const double vr = config_.loop_rotation_sigma * config_.loop_rotation_sigma;
  Matrix6d c = Matrix6d::Zero();
  c.diagonal() << vt, vt, vt, vr, vr, vr;
  return c;
}

bool LoopCloser::pairConsistent(const LoopConstraint& a, const LoopConstraint& b) const {
  const auto chain = [this](int i, int j) {
    return i <= j ? chain_.covarianceBetween(i, j) : chain_.covarianceBetween(j, i);
  };
  const Matrix6d cov = chain(a.query_index, b.query_index) + chain(a.match_index, b.match_index) + 2.0 * loopCovariance();
  const Eigen::Isometry3d T_ma_mb = graph_.pose(a.match_index).inverse() * graph_.pose(b.match_index);
  const Eigen::Isometry3d T_qa_qb = graph_.pose(a.query_index).inverse() * graph_.pose(b.query_index);
  return pairChi2(a.T_match_query, b.T_match_query, T_ma_mb, T_qa_qb, cov) <= config_.max_pair_chi2;
}

// Decides whether a verified loop joins the graph now, waits for a consistent partner, or is rejected.
std::vector<LoopConstraint> LoopCloser::admit(const LoopConstraint& loop) {
  const auto near = [this, &loop](const LoopConstraint& other) {
    return std::abs(other.query_index - loop.query_index) <= config_.consistency_window;
  };
  bool any_near_accepted = false, consistent_with_accepted = false;
  for (const LoopConstraint& a : accepted_) {
    if (!near(a)) continue;
    any_near_accepted = true;
    consistent_with_accepted = consistent_with_accepted || pairConsistent(a, loop);
  }
  if (any_near_accepted) {
    if (consistent_with_accepted) return {loop};
    ++stats_.rejected_pairwise;
    return {};
  }
  if (config_.min_consistent_loops <= 1) return {loop};

  pending_.erase(std::remove_if(pending_.begin(), pending_.end(), [&](const LoopConstraint& p) { return !near(p); }),
                 pending_.end());
  std::vector<LoopConstraint> group;
  std::vector<LoopConstraint> rest;
  for (const LoopConstraint& p : pending_) (pairConsistent(p, loop) ? group : rest).push_back(p);
  if (static_cast<int>(group.size()) + 1 >= config_.min_consistent_loops) {
    group.push_back(loop);
    pending_ = rest;
    stats_.pending = static_cast<int>(pending_.size());
    return group;
  }
  pending_.push_back(loop);
  stats_.pending = static_cast<int>(pending_.size());
  return {};
}

Eigen::Isometry3d LoopCloser::correction(int keyframe) const {
  return graph_.pose(keyframe) * keyframes_[static_cast<std::size_t>(keyframe)].uncorrected.inverse();
}

Trajectory LoopCloser::correctedTrajectory(const Trajectory& uncorrected) const {
  if (keyframes_.empty()) return uncorrected;
  std::vector<std::int64_t> utimes;
  for (const Keyframe& k : keyframes_) utimes.push_back(k.utime);
  const int n = static_cast<int>(keyframes_.size());
  Trajectory out;
  out.reserve(uncorrected.size());
  for (const StampedPose& sp : uncorrected) {
    const int b = static_cast<int>(std::upper_bound(utimes.begin(), utimes.end(), sp.utime) - utimes.begin());
    Eigen::Isometry3d C;
    if (b == 0) {
      C = correction(0);
    } else if (b == n) {
      C = correction(n - 1);
    } else {
      const double span = static_cast<double>(utimes[static_cast<std::size_t>(b)] - utimes[static_cast<std::size_t>(b - 1)]);
      const double s = span > 0 ? static_cast<double>(sp.utime - utimes[static_cast<std::size_t>(b - 1)]) / span : 0.0;
      C = interpolate(correction(b - 1), correction(b), s);
    }
    out.push_back({sp.utime, C * sp.pose});
  }
  return out;
}

std::vector<Eigen::Vector3f> LoopCloser::correctedMap(double voxel) const {
  std::vector<Eigen::Vector3f> points;
  for (std::size_t k = 0; k < keyframes_.size(); ++k) {
    const Eigen::Isometry3f T = graph_.pose(static_cast<int>(k)).cast<float>();
    for (const Eigen::Vector3f& p : keyframes_[k].cloud) points.push_back(T * p);
  }
  return voxelDownsample(points, voxel);
}

}  // namespace adit
