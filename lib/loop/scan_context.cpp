#include "loop/scan_context.hpp"

#include <algorithm>
#include <cmath>

namespace adit {
namespace {

constexpr double kTwoPi = 6.283185307179586;
constexpr float kMinOccupiedValue = 0.01f;

int wrap(int i, int n) { return ((i % n) + n) % n; }

}  // namespace

double yawOfShift(int shift, int sectors) {
  int s = wrap(shift, sectors);
  if (2 * s > sectors) s -= sectors;
  return kTwoPi * static_cast<double>(s) / static_cast<double>(sectors);
}

ScanContext ScanContext::build(const std::vector<Eigen::Vector3f>& points, const ScanContextConfig& config) {
  ScanContext sc;
  const int rings = std::max(1, config.rings);
  const int sectors = std::max(1, config.sectors);
  sc.shift_search_radius_ = std::max(0, config.shift_search_radius);
  sc.descriptor_ = Eigen::MatrixXf::Zero(rings, sectors);
  const double ring_width = config.max_range / rings;
  for (const Eigen::Vector3f& p : points) {
    if (!p.allFinite()) continue;
    const double r = std::hypot(static_cast<double>(p.x()), static_cast<double>(p.y()));
    if (r < config.min_range || r >= config.max_range) continue;
    double angle = std::atan2(static_cast<double>(p.y()), static_cast<double>(p.x()));
    if (angle < 0.0) angle += kTwoPi;
    const int ring = std::min(rings - 1, static_cast<int>(r / ring_width));
    const int sector = std::min(sectors - 1, static_cast<int>(angle / kTwoPi * sectors));
    const float value = std::max(kMinOccupiedValue, static_cast<float>(p.z() + config.height_offset));
    float& bin = sc.descriptor_(ring, sector);
    bin = std::max(bin, value);
  }
  return fromDescriptor(sc.descriptor_, sc.shift_search_radius_);
}

ScanContext ScanContext::fromDescriptor(const Eigen::MatrixXf& descriptor, int shift_search_radius) {
  ScanContext sc;
  sc.descriptor_ = descriptor;
  sc.shift_search_radius_ = shift_search_radius;
  sc.occupied_bins_ = static_cast<int>((sc.descriptor_.array() > 0.0f).count());
  sc.ring_key_ = sc.descriptor_.rowwise().mean();
  sc.sector_key_ = sc.descriptor_.colwise().mean().transpose();
  sc.column_norm_ = sc.descriptor_.colwise().norm().transpose();
  return sc;
}

double ScanContext::distanceAtShift(const ScanContext& other, int shift) const {
  const int n = sectors();
  if (empty() || other.empty() || n != other.sectors() || rings() != other.rings()) return 1.0;
  double similarity = 0.0;
  int columns = 0;
  for (int j = 0; j < n; ++j) {
    const int mine = wrap(j + shift, n);
    const float norms = column_norm_[mine] * other.column_norm_[j];
    if (norms <= 0.0f) continue;
    similarity += static_cast<double>(descriptor_.col(mine).dot(other.descriptor_.col(j)) / norms);
    ++columns;
  }
  if (columns == 0) return 1.0;
  return 1.0 - similarity / columns;
}

// Candidate yaws from the sector keys: the best circular alignment and the best one at least a quarter turn
// away from it. A roadway looks alike driven in either direction, so the second mode is often the true one.
std::vector<int> ScanContext::coarseShifts(const ScanContext& other) const {
  const int n = sectors();
  std::vector<double> cost(n, 0.0);
  for (int s = 0; s < n; ++s)
    for (int j = 0; j < n; ++j) {
      const double d = sector_key_[wrap(j + s, n)] - other.sector_key_[j];
      cost[s] += d * d;
    }
  const int best = static_cast<int>(std::min_element(cost.begin(), cost.end()) - cost.begin());
  int second = -1;
  for (int s = 0; s < n; ++s) {
    const int gap = std::min(wrap(s - best, n), wrap(best - s, n));
    if (4 * gap < n) continue;
    if (second < 0 || cost[s] < cost[second]) second = s;
  }
  std::vector<int> shifts{best};
  if (second >= 0) shifts.push_back(second);
  return shifts;
}

std::pair<double, int> ScanContext::distance(const ScanContext& other) const {
  if (empty() || other.empty() || sectors() != other.sectors() || rings() != other.rings()) return {1.0, 0};
  const int n = sectors();
  double best_distance = 2.0;
  int best_shift = 0;
  // Visit shifts in increasing order so that ties resolve to the same (smallest) shift every run.
  std::vector<int> shifts;
  for (int coarse : coarseShifts(other))
    for (int k = -shift_search_radius_; k <= shift_search_radius_; ++k) shifts.push_back(wrap(coarse + k, n));
  std::sort(shifts.begin(), shifts.end());
  shifts.erase(std::unique(shifts.begin(), shifts.end()), shifts.end());
  for (int s : shifts) {
    const double d = distanceAtShift(other, s);
    if (d < best_distance) {
      best_distance = d;
      best_shift = s;
    }
  }
  return {best_distance, best_shift};
}

}  // namespace adit
