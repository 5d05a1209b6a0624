// map_vs_world <map.pcd> <world.pcd> <ground_truth.tum> <estimate.tum>: how far the points of a saved map
// lie from the simulator's true surfaces. The map is in the estimate's frame; it is placed in the world with
// the rigid (SE(3)) alignment of the whole estimated trajectory onto the ground truth, the alignment `adit
// eval` uses for APE. (Placing it by the first pose alone let a small heading error at the start swing the
// far end of a 300 m run by metres, which hid ghosting behind alignment error.) The world file is a
// dense sampling of the surfaces (`adit sim --world-pcd`), so the nearest world point stands in for the
// surface (bias below half the sampling spacing). Prints: points, mean distance (m), share beyond 0.2 m.
#include "eval/alignment.hpp"
#include "eval/association.hpp"
#include "eval/trajectory_io.hpp"
#include "io/pcd.hpp"
#include "registration/kdtree.hpp"

#include <cmath>
#include <cstdio>

namespace {

std::vector<Eigen::Vector3d> readPoints(const std::string& path) {
  adit::io::PcdFolderConfig config;
  const adit::LidarScan scan = adit::io::readPcdScan(path, config, 0, 0);
  std::vector<Eigen::Vector3d> out;
  for (const adit::LidarPoint& p : scan.points) out.push_back(p.p.cast<double>());
  return out;
}

}  // namespace

int main(int argc, char** argv) {
  if (argc != 5) {
    std::fprintf(stderr, "usage: map_vs_world <map.pcd> <world.pcd> <ground_truth.tum> <estimate.tum>\n");
    return 2;
  }
  try {
    const adit::Trajectory gt = adit::eval::readTum(argv[3]), est = adit::eval::readTum(argv[4]);
    if (gt.empty() || est.empty()) throw std::runtime_error("empty trajectory");
    const adit::eval::AssociatedTrajectories pairs = adit::eval::associate(gt, est);
    if (pairs.est.size() < 3) throw std::runtime_error("fewer than 3 poses match the ground truth in time");
    const adit::eval::Similarity a = adit::eval::solveAlignment(pairs.gt, pairs.est, adit::eval::AlignMode::kSE3);
    Eigen::Isometry3d T_world_map = Eigen::Isometry3d::Identity();
    T_world_map.linear() = a.rotation;
    T_world_map.translation() = a.translation;
    const adit::KdTree3 world(readPoints(argv[2]));
    const std::vector<Eigen::Vector3d> map = readPoints(argv[1]);
    double sum = 0;
    std::size_t far = 0;
    for (const Eigen::Vector3d& p : map) {
      const Eigen::Vector3d q = T_world_map * p;
      const int i = world.nearest(q, 4.0);
      const double d = i < 0 ? 2.0 : (world.point(i) - q).norm();
      sum += d;
      far += d > 0.2 ? 1 : 0;
    }
    const double n = static_cast<double>(std::max<std::size_t>(map.size(), 1));
    std::printf("points=%zu mean_m=%.4f beyond_0.2m=%.4f\n", map.size(), sum / n, static_cast<double>(far) / n);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "map_vs_world: %s\n", e.what());
    return 1;
  }
  return 0;
}
