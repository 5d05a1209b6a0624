#include "view/run_model.hpp"

#include <algorithm>

namespace adit::view {
namespace {

// The pose at exactly `utime` in a time-ordered list (keyframes and ground truth are at sweep times), or nullptr.
const Eigen::Isometry3d* poseAt(const std::vector<TimedPose>& poses, std::int64_t utime) {
  const auto it = std::lower_bound(poses.begin(), poses.end(), utime,
                                   [](const TimedPose& p, std::int64_t t) { return p.utime < t; });
  return it != poses.end() && it->utime == utime ? &it->pose : nullptr;
}

}  // namespace

std::vector<TimedPose> RunModel::correctedTrajectory() const {
  // Correction of each keyframe we can place (its sweep's uncorrected pose known), in time order.
  std::map<std::int64_t, Eigen::Isometry3d> corrections;
  for (const auto& [utime, corrected] : keyframes)
    if (const auto* raw = poseAt(odometry, utime)) corrections[utime] = corrected * raw->inverse();
  std::vector<TimedPose> out;
  out.reserve(odometry.size());
  for (const TimedPose& p : odometry) {
    auto it = corrections.upper_bound(p.utime);
    out.push_back(it == corrections.begin() ? p : TimedPose{p.utime, std::prev(it)->second * p.pose});
  }
  return out;
}

std::vector<std::pair<Eigen::Vector3d, Eigen::Vector3d>> RunModel::loopSegments() const {
  std::vector<std::pair<Eigen::Vector3d, Eigen::Vector3d>> out;
  for (const Loop& loop : loops) {
    const auto q = keyframes.find(loop.query_utime), m = keyframes.find(loop.match_utime);
    if (q != keyframes.end() && m != keyframes.end()) out.emplace_back(q->second.translation(), m->second.translation());
  }
  return out;
}

Eigen::Isometry3d RunModel::groundTruthAlignment() const {
  const Eigen::Isometry3d* gt = odometry.empty() ? nullptr : poseAt(ground_truth, odometry.front().utime);
  return gt ? Eigen::Isometry3d(odometry.front().pose * gt->inverse()) : Eigen::Isometry3d::Identity();
}

std::vector<TimedPose> RunModel::groundTruthInWorld() const {
  const Eigen::Isometry3d align = groundTruthAlignment();
  std::vector<TimedPose> out = ground_truth;
  for (TimedPose& p : out) p.pose = align * p.pose;
  return out;
}

double RunModel::distance() const {
  double d = 0;
  for (std::size_t i = 1; i < odometry.size(); ++i)
    d += (odometry[i].pose.translation() - odometry[i - 1].pose.translation()).norm();
  return d;
}

std::vector<Eigen::Vector3f> RunModel::mapPoints() const {
  std::vector<Eigen::Vector3f> out;
  out.reserve(mapPointCount());
  for (const auto& [id, s] : submaps) {
    const Eigen::Isometry3f T = s.pose.cast<float>();
    for (const auto& p : s.points) out.push_back(T * p);
  }
  return out;
}

std::size_t RunModel::mapPointCount() const {
  std::size_t n = 0;
  for (const auto& [id, s] : submaps) n += s.points.size();
  return n;
}

std::vector<TimedPose> thinTrajectory(const std::vector<TimedPose>& poses, double min_step_m) {
  std::vector<TimedPose> out;
  for (std::size_t i = 0; i < poses.size(); ++i) {
    const bool last = i + 1 == poses.size();
    if (out.empty() || last || (poses[i].pose.translation() - out.back().pose.translation()).norm() >= min_step_m)
      out.push_back(poses[i]);
  }
  return out;
}

}  // namespace adit::view
