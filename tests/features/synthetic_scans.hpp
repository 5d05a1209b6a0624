// Test helper: an analytic ray caster for a 16-beam spinning lidar in scenes of axis-aligned boxes, so
// feature tests know the exact geometry (walls, edges) behind every point.
#pragma once

#include "core/types.hpp"

#include <Eigen/Geometry>

#include <algorithm>
#include <cmath>
#include <functional>
#include <limits>
#include <vector>

namespace adit::test {

struct Box {
  Eigen::Vector3d min, max;
  bool room = false;  // true: the sensor is inside and sees the walls from within; false: a solid block
};

struct Scene {
  std::vector<Box> boxes;

  // Nearest hit distance along the unit ray o + t d (t > 0), infinity if none.
  double cast(const Eigen::Vector3d& o, const Eigen::Vector3d& d) const {
    double best = std::numeric_limits<double>::infinity();
    for (const Box& b : boxes) {
      double t0 = -std::numeric_limits<double>::infinity(), t1 = std::numeric_limits<double>::infinity();
      for (int k = 0; k < 3; ++k) {
        if (std::fabs(d[k]) < 1e-12) {
          if (o[k] < b.min[k] || o[k] > b.max[k]) t0 = std::numeric_limits<double>::infinity();
          continue;
        }
        double a = (b.min[k] - o[k]) / d[k], c = (b.max[k] - o[k]) / d[k];
        if (a > c) std::swap(a, c);
        t0 = std::max(t0, a);
        t1 = std::min(t1, c);
      }
      if (t0 > t1) continue;
      const double t = b.room ? t1 : t0;
      if (t > 1e-6) best = std::min(best, t);
    }
    return best;
  }

  // Distance from p to the nearest box surface (the true geometry).
  double distance(const Eigen::Vector3d& p) const {
    double best = std::numeric_limits<double>::infinity();
    for (const Box& b : boxes) {
      if (b.room) {
        for (int k = 0; k < 3; ++k) best = std::min({best, std::fabs(p[k] - b.min[k]), std::fabs(p[k] - b.max[k])});
      } else {
        const Eigen::Vector3d outside = (b.min - p).cwiseMax(p - b.max).cwiseMax(0.0);
        const double inside = std::min((p - b.min).minCoeff(), (b.max - p).minCoeff());
        best = std::min(best, outside.norm() > 0.0 ? outside.norm() : std::max(inside, 0.0));
      }
    }
    return best;
  }
};

struct LidarModel {
  int beams = 16;              // elevations -15 .. +15 deg (VLP-16 / RS-16), ring 0 lowest
  double az_step_deg = 0.2;    // 1800 columns per sweep at 10 Hz
  float sweep = 0.1f;          // s
  double seam_azimuth = M_PI;  // first column fires facing backwards
  double elevation(int ring) const { return (-15.0 + 30.0 * ring / (beams - 1)) * M_PI / 180.0; }
};

// One sweep, columns fired clockwise (azimuth decreasing) starting at the seam. pose(dt) is T_world_lidar at
// firing time dt (s, <= 0); each point is expressed in the lidar frame at its own firing time (a raw sweep).
inline LidarScan scanScene(const Scene& scene, const std::function<Eigen::Isometry3d(double)>& pose,
                           const LidarModel& m = {}) {
  LidarScan scan;
  scan.sensor = "vlp16";
  scan.num_beams = m.beams;
  scan.sweep_duration = m.sweep;
  scan.has_ring = true;
  scan.has_time = true;
  scan.utime = 1'000'000;
  const int columns = static_cast<int>(std::lround(360.0 / m.az_step_deg));
  for (int k = 0; k < columns; ++k) {
    const double dt = -m.sweep * (1.0 - static_cast<double>(k + 1) / columns);
    const double az = m.seam_azimuth - k * m.az_step_deg * M_PI / 180.0;
    const Eigen::Isometry3d T = pose(dt);
    for (int r = 0; r < m.beams; ++r) {
      const double el = m.elevation(r);
      const Eigen::Vector3d d(std::cos(el) * std::cos(az), std::cos(el) * std::sin(az), std::sin(el));
      const double t = scene.cast(T.translation(), T.linear() * d);
      if (!std::isfinite(t) || t > 100.0) continue;
      LidarPoint p;
      p.p = (t * d).cast<float>();
      p.ring = static_cast<std::uint16_t>(r);
      p.dt = static_cast<float>(dt);
      p.intensity = 1.0f;
      scan.points.push_back(p);
    }
  }
  return scan;
}

inline LidarScan scanScene(const Scene& scene, const Eigen::Isometry3d& T_world_lidar, const LidarModel& m = {}) {
  return scanScene(scene, [&](double) { return T_world_lidar; }, m);
}

// A room 12 x 8 x 4 m (walls from inside: 4 vertical corner edges) around the origin, floor at z = -1.5.
inline Scene boxRoom() { return Scene{{{{-5.0, -3.0, -1.5}, {7.0, 5.0, 2.5}, true}}}; }

// A straight roadway: 4 m wide, 3 m high, 200 m long, floor at z = -1.5 (no vertical edges in reach).
inline Scene corridor() { return Scene{{{{-100.0, -2.0, -1.5}, {100.0, 2.0, 1.5}, true}}}; }

// A wide hall with square pillars (0.6 m) scattered irregularly: many vertical edges for LinK3D.
inline Scene pillarHall() {
  Scene s;
  s.boxes.push_back({{-30.0, -25.0, -1.5}, {35.0, 28.0, 4.0}, true});
  const double xy[][2] = {{4, 2},   {6, -5},  {-3, 7},  {-8, -4}, {12, 9},  {15, -2}, {-14, 3}, {2, -12},
                          {9, 14},  {-6, -13}, {20, 6}, {-18, -9}, {-2, 18}, {18, -14}, {-22, 12}, {25, 0},
                          {7, 21},  {-11, 20}, {13, -20}, {-25, -3}};
  for (const auto& c : xy) {
    const double h = 0.3 + 0.1 * std::fmod(c[0] * c[0] + c[1], 3.0);  // varied widths: 0.6 .. 1.2 m
    s.boxes.push_back({{c[0] - h, c[1] - h, -1.5}, {c[0] + h, c[1] + h, 4.0}, false});
  }
  return s;
}

}  // namespace adit::test
