#include "loop/compact_cloud.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

namespace adit {
namespace {

constexpr float kMaxCount = static_cast<float>(std::numeric_limits<std::int16_t>::max());

}  // namespace

CompactCloud CompactCloud::encode(const std::vector<Eigen::Vector3f>& points, float step) {
  float reach = 0.0f;
  for (const Eigen::Vector3f& p : points)
    if (p.allFinite()) reach = std::max(reach, p.cwiseAbs().maxCoeff());
  CompactCloud out;
  out.step_ = std::max(std::isfinite(step) && step > 0 ? step : 1e-3f, reach / kMaxCount);
  // The step may have been rounded down in float: clamp so the farthest point cannot overflow.
  out.counts_.reserve(points.size() * 3);
  for (const Eigen::Vector3f& p : points) {
    if (!p.allFinite()) continue;
    for (int axis = 0; axis < 3; ++axis) {
      const float count = std::clamp(std::round(p[axis] / out.step_), -kMaxCount, kMaxCount);
      out.counts_.push_back(static_cast<std::int16_t>(count));
    }
  }
  out.counts_.shrink_to_fit();
  return out;
}

std::optional<CompactCloud> CompactCloud::fromCounts(float step, std::vector<std::int16_t> counts) {
  if (!std::isfinite(step) || step <= 0.0f || counts.size() % 3 != 0) return std::nullopt;
  CompactCloud out;
  out.step_ = step;
  out.counts_ = std::move(counts);
  return out;
}

std::vector<Eigen::Vector3f> CompactCloud::decode() const {
  std::vector<Eigen::Vector3f> out;
  out.reserve(size());
  for (std::size_t i = 0; i + 2 < counts_.size(); i += 3)
    out.emplace_back(static_cast<float>(counts_[i]) * step_, static_cast<float>(counts_[i + 1]) * step_,
                     static_cast<float>(counts_[i + 2]) * step_);
  return out;
}

double CompactCloud::maxNorm() const {
  std::int64_t largest = 0;  // squared count vector: at most 3 * 32768^2, exact in 64 bits
  for (std::size_t i = 0; i + 2 < counts_.size(); i += 3) {
    const std::int64_t x = counts_[i], y = counts_[i + 1], z = counts_[i + 2];
    largest = std::max(largest, x * x + y * y + z * z);
  }
  // decode() multiplies in float: a relative rounding of 2^-24 per coordinate, covered with a wide margin.
  return std::sqrt(static_cast<double>(largest)) * static_cast<double>(step_) * (1.0 + 1e-5);
}

}  // namespace adit
