#include "odometry/startup_search.hpp"

#include <algorithm>
#include <cmath>

namespace adit {

std::vector<Eigen::Isometry3d> startupHypotheses(const Eigen::Isometry3d& prior, double max_distance_m, double step_m) {
  std::vector<Eigen::Isometry3d> out{prior};
  if (!(step_m > 0.0) || !(max_distance_m >= step_m)) return out;
  const int steps = static_cast<int>(std::floor(max_distance_m / step_m + 1e-9));
  if (prior.translation().squaredNorm() > 0.0) {  // a seed with motion (LinK3D): also try standing still
    Eigen::Isometry3d still = prior;
    still.translation().setZero();
    out.push_back(still);
  }
  for (int k = 1; k <= steps; ++k) {
    for (const double sign : {1.0, -1.0}) {
      Eigen::Isometry3d T = prior;
      T.translation() = Eigen::Vector3d(sign * k * step_m, 0.0, 0.0);
      out.push_back(T);
    }
  }
  return out;
}

std::size_t screenStride(std::size_t points, int screen_points) {
  if (screen_points <= 0) return 1;
  const auto wanted = static_cast<std::size_t>(screen_points);
  return std::max<std::size_t>(1, points / wanted);
}

int inlierCount(const Correspondences& matches, const Eigen::Isometry3d& T, double max_residual_m) {
  int count = 0;
  for (const LineMatch& m : matches.lines) {
    const Eigen::Vector3d d = T * m.point - m.on_line;
    if ((d - m.direction * m.direction.dot(d)).norm() < max_residual_m) ++count;
  }
  for (const PlaneMatch& m : matches.planes)
    if (std::fabs(m.normal.dot(T * m.point) + m.offset) < max_residual_m) ++count;
  return count;
}

}  // namespace adit
