#include "sim/path.hpp"

#include <algorithm>
#include <cmath>

namespace adit::sim {

void Path2d::addPiece(const Eigen::Vector2d& start, double heading, double curvature, double length) {
  if (length <= 1e-9) return;
  pieces_.push_back({start, heading, curvature, length_, length});
  length_ += length;
}

Path2d::Path2d(const std::vector<Eigen::Vector2d>& waypoints, double corner_radius) {
  // Drop repeated points so every segment has a direction.
  std::vector<Eigen::Vector2d> pts;
  for (const auto& p : waypoints)
    if (pts.empty() || (p - pts.back()).norm() > 1e-6) pts.push_back(p);
  if (pts.size() < 2) return;
  Eigen::Vector2d cursor = pts[0];
  for (std::size_t i = 1; i < pts.size(); ++i) {
    const Eigen::Vector2d d_in = (pts[i] - pts[i - 1]).normalized();
    const double heading_in = std::atan2(d_in.y(), d_in.x());
    if (i + 1 == pts.size()) {
      addPiece(cursor, heading_in, 0.0, (pts[i] - cursor).norm());
      break;
    }
    const Eigen::Vector2d d_out = (pts[i + 1] - pts[i]).normalized();
    const double turn = std::atan2(d_in.x() * d_out.y() - d_in.y() * d_out.x(), d_in.dot(d_out));
    if (std::fabs(turn) < 1e-6) continue;  // straight through: the straight piece continues
    // Tangent length of the fillet; keep it within 45 % of both neighbouring segments.
    const double half_tan = std::tan(std::fabs(turn) / 2);
    const double max_tangent = 0.45 * std::min((pts[i] - pts[i - 1]).norm(), (pts[i + 1] - pts[i]).norm());
    const double radius = std::min(corner_radius, max_tangent / half_tan);
    const double tangent = radius * half_tan;
    const Eigen::Vector2d arc_start = pts[i] - d_in * tangent;
    addPiece(cursor, heading_in, 0.0, (arc_start - cursor).norm());
    addPiece(arc_start, heading_in, (turn > 0 ? 1.0 : -1.0) / radius, radius * std::fabs(turn));
    cursor = pts[i] + d_out * tangent;
  }
}

Path2d::Sample Path2d::at(double s) const {
  Sample out;
  if (pieces_.empty()) return out;
  s = std::clamp(s, 0.0, length_);
  auto it = std::upper_bound(pieces_.begin(), pieces_.end(), s, [](double v, const Piece& p) { return v < p.s0; });
  const Piece& p = *(it == pieces_.begin() ? it : std::prev(it));
  const double ds = std::min(s - p.s0, p.length);
  const double h = p.heading0 + p.curvature * ds;
  out.heading = h;
  out.curvature = p.curvature;
  if (std::fabs(p.curvature) < 1e-12) {
    out.position = p.start + ds * Eigen::Vector2d(std::cos(p.heading0), std::sin(p.heading0));
  } else {
    const double k = p.curvature;
    out.position = p.start + Eigen::Vector2d((std::sin(h) - std::sin(p.heading0)) / k,
                                             (std::cos(p.heading0) - std::cos(h)) / k);
  }
  return out;
}

}  // namespace adit::sim
