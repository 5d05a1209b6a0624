// A drivable 2D path: a polyline of waypoints whose corners are rounded by circular arcs, parameterised by
// arc length. Heading is continuous, curvature piecewise constant (0 on straights, 1/r on arcs).
#pragma once

#include <Eigen/Core>

#include <vector>

namespace adit::sim {

class Path2d {
 public:
  Path2d() = default;
  // Corners get arcs of radius `corner_radius`, shrunk where the neighbouring segments are too short.
  Path2d(const std::vector<Eigen::Vector2d>& waypoints, double corner_radius);

  struct Sample {
    Eigen::Vector2d position = Eigen::Vector2d::Zero();
    double heading = 0.0;    // rad, counter-clockwise from +x
    double curvature = 0.0;  // 1/m, positive when turning left
  };
  // s is clamped to [0, length()].
  Sample at(double s) const;
  double length() const { return length_; }
  bool empty() const { return pieces_.empty(); }

 private:
  struct Piece {
    Eigen::Vector2d start;
    double heading0, curvature, s0, length;
  };
  void addPiece(const Eigen::Vector2d& start, double heading, double curvature, double length);
  std::vector<Piece> pieces_;
  double length_ = 0.0;
};

}  // namespace adit::sim
