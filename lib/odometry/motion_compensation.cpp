#include "odometry/motion_compensation.hpp"

#include "core/geometry.hpp"

#include <algorithm>
#include <array>

namespace adit {

void compensateMotion(std::vector<LidarPoint>& points, const Eigen::Isometry3d& T_prev_curr, double gap_s) {
  if (!(gap_s > 1e-3) || !T_prev_curr.matrix().allFinite() || points.empty()) return;
  // Poses tabulated over the gap; points blend the two nearest (a slerp per point would cost ~10 ms on a
  // 120k-point sweep, the table ~1 ms, and the blend of matrices 1/32 of a sweep apart stays orthonormal).
  constexpr int kSteps = 32;
  const Eigen::Isometry3d back = T_prev_curr.inverse();
  std::array<Eigen::Matrix3f, kSteps + 1> R;
  std::array<Eigen::Vector3f, kSteps + 1> t;
  for (int k = 0; k <= kSteps; ++k) {
    const Eigen::Isometry3d T = interpolate(Eigen::Isometry3d::Identity(), back, static_cast<double>(k) / kSteps);
    R[k] = T.linear().cast<float>();
    t[k] = T.translation().cast<float>();
  }
  for (LidarPoint& p : points) {
    if (!(p.dt < 0.0f)) continue;  // dt = 0 (or NaN): already at the end instant
    const double u = std::min(1.0, -static_cast<double>(p.dt) / gap_s) * kSteps;
    const int k = std::min(static_cast<int>(u), kSteps - 1);
    const float f = static_cast<float>(u - k);
    p.p = ((1.0f - f) * R[k] + f * R[k + 1]) * p.p + (1.0f - f) * t[k] + f * t[k + 1];
  }
}

}  // namespace adit
