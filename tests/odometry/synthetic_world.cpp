#include "synthetic_world.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <random>

namespace adit::test {
namespace {

// Ray/box distance: exit distance for a box we are inside, entry distance for a solid one; inf if missed.
double hitDistance(const Box& b, const Eigen::Vector3d& o, const Eigen::Vector3d& d) {
  double t_near = -std::numeric_limits<double>::infinity(), t_far = std::numeric_limits<double>::infinity();
  for (int i = 0; i < 3; ++i) {
    if (std::abs(d[i]) < 1e-12) {
      if (o[i] < b.min[i] || o[i] > b.max[i]) return std::numeric_limits<double>::infinity();
      continue;
    }
    double t0 = (b.min[i] - o[i]) / d[i], t1 = (b.max[i] - o[i]) / d[i];
    if (t0 > t1) std::swap(t0, t1);
    t_near = std::max(t_near, t0);
    t_far = std::min(t_far, t1);
  }
  if (t_near > t_far) return std::numeric_limits<double>::infinity();
  if (b.inside) return t_far > 0 ? t_far : std::numeric_limits<double>::infinity();
  return t_near > 1e-6 ? t_near : std::numeric_limits<double>::infinity();
}

// Distance of a hit to the nearest edge of its box: the second-smallest distance to a face plane.
double edgeDistance(const Box& b, const Eigen::Vector3d& p) {
  double d[3];
  for (int i = 0; i < 3; ++i) d[i] = std::min(std::abs(p[i] - b.min[i]), std::abs(p[i] - b.max[i]));
  std::sort(d, d + 3);
  return d[1];
}

struct Hit {
  LidarPoint point;
  double edge_distance;
};

// Labels one ring like a LOAM extractor would: along the ring, a run of hits near a box edge is one
// high-curvature spot; its hit closest to the edge is sharp, that hit and its run neighbours are less sharp.
// Every other hit is a surface point, a regular subset flat.
void labelRing(const std::vector<Hit>& ring, double band, FeatureSet& f) {
  int surf_count = 0;
  for (std::size_t i = 0; i < ring.size();) {
    if (ring[i].edge_distance >= band) {
      if (surf_count % 4 == 0) f.surf_less_flat.push_back(ring[i].point);
      if (surf_count % 48 == 0) f.surf_flat.push_back(ring[i].point);
      ++surf_count, ++i;
      continue;
    }
    std::size_t end = i, best = i;
    while (end < ring.size() && ring[end].edge_distance < band) {
      if (ring[end].edge_distance < ring[best].edge_distance) best = end;
      ++end;
    }
    f.corner_sharp.push_back(ring[best].point);
    for (std::size_t k = (best > i ? best - 1 : best); k <= std::min(best + 1, end - 1); ++k)
      f.corner_less_sharp.push_back(ring[k].point);
    i = end;
  }
}

bool nearRange(const Box& b, const Eigen::Vector3d& o, double range) {
  const Eigen::Vector3d closest = o.cwiseMax(b.min).cwiseMin(b.max);
  return b.inside || (closest - o).norm() < range;
}

}  // namespace

Eigen::Isometry3d poseFrom(double x, double y, double z, double roll, double pitch, double yaw) {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = (Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitZ()) * Eigen::AngleAxisd(pitch, Eigen::Vector3d::UnitY()) *
                Eigen::AngleAxisd(roll, Eigen::Vector3d::UnitX()))
                   .toRotationMatrix();
  T.translation() = Eigen::Vector3d(x, y, z);
  return T;
}

World boxRoom() {
  World w;
  w.boxes.push_back({{-12, -8, -1.5}, {14, 7, 4.0}, true});
  w.boxes.push_back({{3, 2, -1.5}, {4, 3, 4.0}, false});      // pillars
  w.boxes.push_back({{-6, -4, -1.5}, {-5, -3, 4.0}, false});
  w.boxes.push_back({{8, -5, -1.5}, {8.6, -4.4, 4.0}, false});
  w.boxes.push_back({{-3, 4, -1.5}, {-1, 5.5, 0.5}, false});  // crates
  w.boxes.push_back({{5, -3, -1.5}, {6.5, -2, -0.2}, false});
  return w;
}

World featurelessCorridor() {
  World w;
  w.boxes.push_back({{-1000, -2, -1.2}, {1000, 2, 2.3}, true});
  return w;
}

void addWallPillars(World& world, double from_x, double to_x, double spacing) {
  int k = 0;
  for (double x = from_x; x < to_x; x += spacing, ++k) {
    const double y0 = (k % 2 == 0) ? -2.5 : 2.1;  // 0.4 m deep pillars on alternating walls
    world.boxes.push_back({{x, y0, -1.2}, {x + 0.5, y0 + 0.4, 2.5}, false});
  }
}

World roadwayWithPillars(double length, double spacing) {
  World w;
  w.boxes.push_back({{-50, -2.5, -1.2}, {length + 50, 2.5, 2.5}, true});
  addWallPillars(w, -40, length + 40, spacing);
  return w;
}

FeatureSet simulateSweep(const World& world, const Eigen::Isometry3d& T, const LidarModel& lidar, std::int64_t utime,
                         std::uint32_t seed) {
  std::mt19937 rng(seed);
  std::normal_distribution<double> noise(0.0, lidar.range_noise);
  const Eigen::Vector3d origin = T.translation();
  std::vector<const Box*> visible;
  for (const Box& b : world.boxes)
    if (nearRange(b, origin, lidar.max_range)) visible.push_back(&b);

  FeatureSet f;
  f.utime = utime;
  f.cloud.utime = utime;
  f.cloud.num_beams = lidar.beams;
  f.cloud.has_ring = true;
  f.cloud.deskewed = true;
  const double deg = M_PI / 180.0;
  for (int ring = 0; ring < lidar.beams; ++ring) {
    const double el = (lidar.min_elevation_deg + (lidar.max_elevation_deg - lidar.min_elevation_deg) * ring /
                                                     std::max(1, lidar.beams - 1)) * deg;
    std::vector<Hit> hits;
    for (int a = 0; a < lidar.azimuth_steps; ++a) {
      const double az = 2.0 * M_PI * a / lidar.azimuth_steps;
      const Eigen::Vector3d dir_l(std::cos(el) * std::cos(az), std::cos(el) * std::sin(az), std::sin(el));
      const Eigen::Vector3d dir_w = T.linear() * dir_l;
      double best = std::numeric_limits<double>::infinity();
      const Box* hit = nullptr;
      for (const Box* b : visible) {
        const double t = hitDistance(*b, origin, dir_w);
        if (t < best) best = t, hit = b;
      }
      if (!hit || best > lidar.max_range) continue;
      LidarPoint p;
      p.p = ((best + noise(rng)) * dir_l).cast<float>();
      p.ring = static_cast<std::uint16_t>(ring);
      f.cloud.points.push_back(p);
      hits.push_back({p, edgeDistance(*hit, origin + best * dir_w)});
    }
    labelRing(hits, lidar.edge_band, f);
  }
  return f;
}

}  // namespace adit::test
