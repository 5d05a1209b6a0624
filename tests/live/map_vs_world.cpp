// map_vs_world <map.pcd> <world.pcd> <ground_truth.tum> <estimate.tum>: how far the points of a saved map
// lie from the simulator's true surfaces (eval/map_accuracy.hpp), the map placed in the world by the rigid
// (SE(3)) alignment of the whole estimated trajectory onto the ground truth, as `adit eval` aligns for APE.
// The world file is a dense sampling of the surfaces (`adit sim --world-pcd`). Prints: points, mean and
// 95th-percentile distance (m), share beyond 0.2 m.
#include "eval/alignment.hpp"
#include "eval/association.hpp"
#include "eval/trajectory_io.hpp"
#include "io/pcd.hpp"
#include "eval/map_accuracy.hpp"

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
    const adit::eval::MapAccuracy m = adit::eval::mapAgainstWorld(readPoints(argv[1]), readPoints(argv[2]), a);
    if (!m.valid) throw std::runtime_error("an empty map or world");
    std::printf("points=%zu mean_m=%.4f p95_m=%.4f beyond_0.2m=%.4f\n", m.points, m.mean_m, m.p95_m, m.beyond_02_m);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "map_vs_world: %s\n", e.what());
    return 1;
  }
  return 0;
}
