#include "eval/map_accuracy.hpp"

#include "registration/kdtree.hpp"

#include <Eigen/Eigenvalues>

#include <algorithm>

namespace adit::eval {
namespace {

// Distance from q to the surface the samples around it describe: to the plane fitted through its nearest
// samples (so the sampling spacing adds no bias on flat and gently curved walls), or to the nearest sample
// where there are too few to fit one (an edge of the world). max_distance_m when no sample is that near.
double surfaceDistance(const KdTree3& world, const Eigen::Vector3d& q, double max_distance_m, std::vector<int>& near) {
  world.nearestK(q, 6, max_distance_m * max_distance_m, near);
  if (near.empty()) return max_distance_m;
  const double to_nearest = (world.point(near.front()) - q).norm();
  if (near.size() < 4) return to_nearest;
  Eigen::Vector3d mean = Eigen::Vector3d::Zero();
  for (const int i : near) mean += world.point(i);
  mean /= static_cast<double>(near.size());
  Eigen::Matrix3d cov = Eigen::Matrix3d::Zero();
  for (const int i : near) cov += (world.point(i) - mean) * (world.point(i) - mean).transpose();
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig(cov);
  // Not a plane (a corner, samples along a line): the nearest sample is the honest answer.
  if (eig.eigenvalues()(0) > 0.1 * eig.eigenvalues()(1)) return to_nearest;
  return std::min(to_nearest, std::abs(eig.eigenvectors().col(0).dot(q - mean)));
}

}  // namespace

MapAccuracy mapAgainstWorld(const std::vector<Eigen::Vector3d>& map, const std::vector<Eigen::Vector3d>& surface,
                            const Similarity& map_to_world, double max_distance_m) {
  MapAccuracy a;
  if (map.empty() || surface.empty()) return a;
  const KdTree3 world(surface);
  std::vector<double> d;
  d.reserve(map.size());
  std::vector<int> near;
  for (const Eigen::Vector3d& p : map)
    d.push_back(surfaceDistance(world, map_to_world.scale * (map_to_world.rotation * p) + map_to_world.translation,
                                max_distance_m, near));
  a.valid = true;
  a.points = map.size();
  double sum = 0;
  std::size_t far = 0;
  for (const double x : d) {
    sum += x;
    far += x > 0.2 ? 1 : 0;
  }
  const double n = static_cast<double>(d.size());
  a.mean_m = sum / n;
  a.beyond_02_m = static_cast<double>(far) / n;
  const auto k = static_cast<std::size_t>(0.95 * (n - 1));
  std::nth_element(d.begin(), d.begin() + static_cast<std::ptrdiff_t>(k), d.end());
  a.p95_m = d[k];
  return a;
}

}  // namespace adit::eval
