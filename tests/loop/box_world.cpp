#include "box_world.hpp"

#include <array>
#include <cmath>
#include <limits>
#include <random>

namespace adit::testing {

void BoxWorld::addFloorAndRoof(double x0, double y0, double x1, double y1, double height) {
  add(x0, y0, -1.0, x1, y1, 0.0);
  add(x0, y0, height, x1, y1, height + 1.0);
}

namespace {

// Distance along the ray to the box, or +inf when missed or when the origin is inside it.
double hit(const Box& b, const Eigen::Vector3d& o, const Eigen::Vector3d& d) {
  double t0 = 0.0, t1 = std::numeric_limits<double>::infinity();
  for (int i = 0; i < 3; ++i) {
    if (std::abs(d[i]) < 1e-12) {
      if (o[i] < b.lo[i] || o[i] > b.hi[i]) return std::numeric_limits<double>::infinity();
      continue;
    }
    double a = (b.lo[i] - o[i]) / d[i], c = (b.hi[i] - o[i]) / d[i];
    if (a > c) std::swap(a, c);
    t0 = std::max(t0, a);
    t1 = std::min(t1, c);
    if (t0 > t1) return std::numeric_limits<double>::infinity();
  }
  return t0 > 1e-9 ? t0 : std::numeric_limits<double>::infinity();
}

}  // namespace

LidarScan simulateSweep(const BoxWorld& world, const Eigen::Isometry3d& T_world_lidar, std::uint32_t seed,
                        int azimuth_steps, double range_noise, double max_range) {
  std::mt19937 rng(seed);
  std::normal_distribution<double> noise(0.0, range_noise);
  LidarScan scan;
  scan.sensor = "vlp16";
  scan.num_beams = 16;
  scan.has_ring = true;
  scan.deskewed = true;
  const Eigen::Vector3d origin = T_world_lidar.translation();
  for (int a = 0; a < azimuth_steps; ++a) {
    const double az = 2.0 * M_PI * a / azimuth_steps;
    for (int ring = 0; ring < 16; ++ring) {
      const double el = (-15.0 + 2.0 * ring) * M_PI / 180.0;
      const Eigen::Vector3d dir_l(std::cos(el) * std::cos(az), std::cos(el) * std::sin(az), std::sin(el));
      const Eigen::Vector3d dir_w = T_world_lidar.linear() * dir_l;
      double best = std::numeric_limits<double>::infinity();
      for (const Box& b : world.boxes) best = std::min(best, hit(b, origin, dir_w));
      if (!(best < max_range)) continue;
      LidarPoint p;
      p.p = ((best + noise(rng)) * dir_l).cast<float>();
      p.ring = static_cast<std::uint16_t>(ring);
      scan.points.push_back(p);
    }
  }
  return scan;
}

std::vector<Eigen::Vector3f> positions(const LidarScan& scan) {
  std::vector<Eigen::Vector3f> out;
  for (const LidarPoint& p : scan.points) out.push_back(p.p);
  return out;
}

Eigen::Isometry3d poseXYYaw(double x, double y, double z, double yaw) {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  T.translation() = Eigen::Vector3d(x, y, z);
  return T;
}

}  // namespace adit::testing

namespace adit::testing {

BoxWorld makeRoadway(std::uint32_t seed, double width, int features, bool cross_cut, double x0, double x1) {
  BoxWorld w;
  const double h = width / 2.0;
  w.addFloorAndRoof(x0 - 5, -30, x1 + 5, 30, 4.0);
  w.add(x0 - 5, -h - 2, 0, x0, h + 2, 4);  // end faces
  w.add(x1, -h - 2, 0, x1 + 5, h + 2, 4);
  if (cross_cut) {  // left wall interrupted by a 4 m wide side roadway going to y = +25
    w.add(x0, h, 0, -2.0, h + 2, 4);
    w.add(2.0, h, 0, x1, h + 2, 4);
    w.add(-4.0, h, 0, -2.0, 25, 4);
    w.add(2.0, h, 0, 4.0, 25, 4);
    w.add(-4.0, 25, 0, 4.0, 27, 4);
  } else {
    w.add(x0, h, 0, x1, h + 2, 4);
  }
  w.add(x0, -h - 2, 0, x1, -h, 4);
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> along(x0 + 5, x1 - 5), len(0.6, 3.0), depth(0.3, 1.2), top(0.8, 3.5);
  // Roof falls and overbreak: the roof height changes along the roadway.
  std::uniform_real_distribution<double> sag(0.3, 1.2), sag_len(3.0, 10.0);
  for (int i = 0; i < features / 2; ++i) {
    const double x = along(rng);
    w.add(x, -h, 4.0 - sag(rng), x + sag_len(rng), h, 4.0);
  }
  for (int i = 0; i < features; ++i) {
    const double x = along(rng), l = len(rng), d = depth(rng), z = top(rng);
    if (i % 2 == 0)
      w.add(x, h - d, 0, x + l, h, z);
    else
      w.add(x, -h, 0, x + l, -h + d, z);
  }
  return w;
}

BoxWorld makePeriodicRoadway(std::uint32_t seed, double period, int boxes, double half_width, int first, int last) {
  BoxWorld world;
  world.addFloorAndRoof(-200, -10, 300, 10, 4.0);
  world.add(-200, half_width, 0, 300, half_width + 2, 4);
  world.add(-200, -half_width - 2, 0, 300, -half_width, 4);
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  std::vector<std::array<double, 4>> pattern;  // x in the period, length, depth, top
  for (int i = 0; i < boxes; ++i) pattern.push_back({period * u(rng), 0.6 + 2 * u(rng), 0.4 + 0.8 * u(rng), 0.8 + 2.7 * u(rng)});
  for (int k = first; k <= last; ++k)
    for (std::size_t i = 0; i < pattern.size(); ++i) {
      const auto& [x, len, d, z] = pattern[i];
      const double x0 = x + period * k;
      if (i % 2 == 0) world.add(x0, half_width - d, 0, x0 + len, half_width, z);
      else world.add(x0, -half_width, 0, x0 + len, -half_width + d, z);
    }
  return world;
}

}  // namespace adit::testing
