#include "map/map_products.hpp"

#include "eval/trajectory_io.hpp"
#include "io/pcd.hpp"

#include <filesystem>
#include <stdexcept>

namespace adit {

MapProductNames productNamesFor(const std::string& argument) {
  if (argument.empty()) return {};
  std::string stem = argument;
  const std::string ext = ".pcd";
  if (stem.size() > ext.size() && stem.compare(stem.size() - ext.size(), ext.size(), ext) == 0)
    stem.resize(stem.size() - ext.size());
  return {stem + ".pcd", stem + ".tum", stem + ".g2o"};
}

std::vector<std::string> writeMapProducts(const LoopCloser& closer, const Trajectory& uncorrected, double map_voxel,
                                          const std::string& dir, const MapProductNames& names) {
  namespace fs = std::filesystem;
  const std::string map = (fs::path(dir) / names.map).string();
  const std::string trajectory = (fs::path(dir) / names.trajectory).string();
  const std::string graph = (fs::path(dir) / names.graph).string();
  std::vector<LidarPoint> points;
  for (const auto& p : closer.correctedMap(map_voxel)) points.push_back({p, 0.0f, 0, 0.0f});
  io::writePcd(map, points);
  eval::writeTum(trajectory, closer.correctedTrajectory(uncorrected));
  if (!saveG2o(closer.graph(), graph)) throw std::runtime_error("cannot write " + graph);
  return {map, trajectory, graph};
}

}  // namespace adit
