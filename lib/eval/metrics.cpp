#include "eval/metrics.hpp"

#include <algorithm>
#include <cmath>

namespace adit::eval {
namespace {

constexpr double kRadToDeg = 180.0 / M_PI;

// Rotation angle in [0, pi]. atan2 of sine (from the skew part) and cosine (from the trace) stays
// accurate near 0, where acos of the trace alone loses ~1e-8 rad.
double angleOf(const Eigen::Matrix3d& R) {
  const Eigen::Vector3d skew(R(2, 1) - R(1, 2), R(0, 2) - R(2, 0), R(1, 0) - R(0, 1));
  return std::atan2(0.5 * skew.norm(), 0.5 * (R.trace() - 1.0));
}

}  // namespace

ErrorStats computeStats(std::vector<double> errors) {
  ErrorStats s;
  s.count = errors.size();
  if (errors.empty()) return s;
  const double n = static_cast<double>(errors.size());
  double sum = 0.0, sum_sq = 0.0;
  for (double e : errors) {
    sum += e;
    sum_sq += e * e;
  }
  s.mean = sum / n;
  s.rmse = std::sqrt(sum_sq / n);
  double var = 0.0;
  for (double e : errors) var += (e - s.mean) * (e - s.mean);
  s.std = std::sqrt(var / n);
  std::sort(errors.begin(), errors.end());
  s.min = errors.front();
  s.max = errors.back();
  const std::size_t mid = errors.size() / 2;
  s.median = errors.size() % 2 ? errors[mid] : 0.5 * (errors[mid - 1] + errors[mid]);
  return s;
}

std::vector<double> apeTranslation(const Trajectory& gt, const Trajectory& est) {
  std::vector<double> out;
  const std::size_t n = std::min(gt.size(), est.size());
  out.reserve(n);
  for (std::size_t k = 0; k < n; ++k) out.push_back((est[k].pose.translation() - gt[k].pose.translation()).norm());
  return out;
}

double pathLength(const Trajectory& trajectory) {
  double length = 0.0;
  for (std::size_t k = 1; k < trajectory.size(); ++k)
    length += (trajectory[k].pose.translation() - trajectory[k - 1].pose.translation()).norm();
  return length;
}

std::vector<std::pair<std::size_t, std::size_t>> pairsByPathLength(const Trajectory& poses, double delta_m) {
  std::vector<std::size_t> ids;
  double current = 0.0;
  for (std::size_t i = 0; i < poses.size(); ++i) {
    if (i > 0) current += (poses[i].pose.translation() - poses[i - 1].pose.translation()).norm();
    if (current >= delta_m) {
      ids.push_back(i);
      current = 0.0;
    }
  }
  std::vector<std::pair<std::size_t, std::size_t>> pairs;
  for (std::size_t k = 1; k < ids.size(); ++k) pairs.emplace_back(ids[k - 1], ids[k]);
  return pairs;
}

RelativeErrors relativeErrors(const Trajectory& gt, const Trajectory& est,
                              const std::vector<std::pair<std::size_t, std::size_t>>& pairs) {
  RelativeErrors out;
  for (const auto& [i, j] : pairs) {
    if (i >= gt.size() || j >= gt.size() || i >= est.size() || j >= est.size()) continue;
    const Eigen::Isometry3d Q = gt[i].pose.inverse() * gt[j].pose;
    const Eigen::Isometry3d P = est[i].pose.inverse() * est[j].pose;
    const Eigen::Isometry3d E = Q.inverse() * P;
    out.translation_m.push_back(E.translation().norm());
    out.rotation_deg.push_back(angleOf(E.linear()) * kRadToDeg);
  }
  return out;
}

KittiDrift kittiDrift(const Trajectory& gt, const Trajectory& est, const std::vector<double>& lengths_m,
                      std::size_t step_frames) {
  KittiDrift out;
  const std::size_t n = std::min(gt.size(), est.size());
  if (n < 2 || step_frames == 0) return out;
  std::vector<double> dist(n, 0.0);  // gt distance from the start
  for (std::size_t k = 1; k < n; ++k)
    dist[k] = dist[k - 1] + (gt[k].pose.translation() - gt[k - 1].pose.translation()).norm();

  std::vector<DriftLength> acc(lengths_m.size());
  double t_sum = 0.0, r_sum = 0.0;
  for (std::size_t first = 0; first < n; first += step_frames) {
    for (std::size_t l = 0; l < lengths_m.size(); ++l) {
      const double L = lengths_m[l];
      const auto last_it = std::upper_bound(dist.begin() + static_cast<std::ptrdiff_t>(first), dist.end(), dist[first] + L);
      if (last_it == dist.end() || L <= 0.0) continue;
      const std::size_t last = static_cast<std::size_t>(last_it - dist.begin());
      const Eigen::Isometry3d dq = gt[first].pose.inverse() * gt[last].pose;
      const Eigen::Isometry3d dp = est[first].pose.inverse() * est[last].pose;
      const Eigen::Isometry3d e = dp.inverse() * dq;
      const double t_err = e.translation().norm() / L, r_err = angleOf(e.linear()) / L;
      acc[l].segments++;
      acc[l].translation_percent += t_err;
      acc[l].rotation_deg_per_m += r_err;
      t_sum += t_err;
      r_sum += r_err;
      out.segments++;
    }
  }
  if (out.segments == 0) return out;
  out.available = true;
  out.translation_percent = 100.0 * t_sum / static_cast<double>(out.segments);
  out.rotation_deg_per_m = kRadToDeg * r_sum / static_cast<double>(out.segments);
  for (std::size_t l = 0; l < lengths_m.size(); ++l) {
    if (acc[l].segments == 0) continue;
    const double m = static_cast<double>(acc[l].segments);
    out.per_length.push_back({lengths_m[l], acc[l].segments, 100.0 * acc[l].translation_percent / m,
                              kRadToDeg * acc[l].rotation_deg_per_m / m});
  }
  return out;
}

}  // namespace adit::eval
