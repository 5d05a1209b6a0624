// Files a node leaves behind at the end of a run (map, trajectories, graph). `adit replay` asks every node
// that implements this, in pipeline order, so a later stage's product replaces an earlier one's: the
// mapper writes map.pcd, odometry.tum and trajectory.tum; the loop closer then rewrites trajectory.tum and
// map.pcd from the corrected keyframe poses.
#pragma once

#include <string>
#include <vector>

namespace adit {
struct MapBundle;
}

namespace adit::nodes {

class WritesProducts {
 public:
  virtual ~WritesProducts() = default;
  // Writes atomically into out_dir; returns the paths written.
  virtual std::vector<std::string> writeProducts(const std::string& out_dir) = 0;
  // Whether this node's products include map.pcd; a node whose map a later one replaces is told so before
  // the first input (mapWrittenLater) and need not build its own.
  virtual bool writesMap() const { return false; }
  virtual void mapWrittenLater() {}
};

// The map owner (the loop closer) also writes a map bundle (map/map_bundle.hpp) for later runs to start from.
class WritesBundle {
 public:
  virtual ~WritesBundle() = default;
  // The run as a bundle (joined to the saved map when extending one); throws std::runtime_error naming what
  // failed. map/map_bundle.hpp writeMapBundle writes it.
  virtual MapBundle mapBundle() = 0;
};

}  // namespace adit::nodes
