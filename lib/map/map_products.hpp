// The run's products from the map owner (the loop closer): the corrected map (every keyframe's cloud at
// its corrected pose, voxel-downsampled), the corrected trajectory (every sweep's pose, corrected by the
// keyframes around it) and the pose graph. Live `save_map`, a clean stop and `adit replay` all write them
// through here, so they agree on the same input.
#pragma once

#include "core/types.hpp"
#include "loop/loop_closer.hpp"

#include <string>
#include <vector>

namespace adit {

struct MapProductNames {
  std::string map = "map.pcd";
  std::string trajectory = "trajectory.tum";
  std::string graph = "pose_graph.g2o";
};

// Names for a save_map argument "NAME" or "NAME.pcd": NAME.pcd, NAME.tum, NAME.g2o ("" = the defaults).
MapProductNames productNamesFor(const std::string& argument);

// Writes the three files atomically into dir; returns their paths. Throws (naming the file) if one cannot be
// written; files already written stay, and the one that failed keeps its previous content.
std::vector<std::string> writeMapProducts(const LoopCloser& closer, const Trajectory& uncorrected, double map_voxel,
                                          const std::string& dir, const MapProductNames& names = {});

}  // namespace adit
