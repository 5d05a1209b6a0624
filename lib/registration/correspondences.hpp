// Geometric correspondences handed to the solver: a source point (lidar frame of the sweep being
// registered) and the line or plane it should lie on, expressed in the reference frame (previous sweep's
// lidar frame for odometry, world for mapping).
#pragma once

#include <Eigen/Core>

#include <vector>

namespace adit {

struct LineMatch {
  Eigen::Vector3d point;      // source point, sweep lidar frame
  Eigen::Vector3d on_line;    // a point of the line, reference frame
  Eigen::Vector3d direction;  // unit direction of the line, reference frame
};

struct PlaneMatch {
  Eigen::Vector3d point;   // source point, sweep lidar frame
  Eigen::Vector3d normal;  // unit normal, reference frame
  double offset = 0.0;     // plane: normal . x + offset = 0
};

struct Correspondences {
  std::vector<LineMatch> lines;
  std::vector<PlaneMatch> planes;
  std::size_t size() const { return lines.size() + planes.size(); }
};

}  // namespace adit
