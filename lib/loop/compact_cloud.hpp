// A keyframe's cloud kept compactly: each coordinate an int16 count of a fixed step in the keyframe's lidar
// frame, 6 bytes a point instead of 12. The loop closer keeps one per keyframe for the whole run (ICP
// verification, the corrected map), so over a long run these clouds are most of its memory; they are
// decoded only when a loop job or the map needs them.
#pragma once

#include <Eigen/Core>

#include <cstdint>
#include <optional>
#include <vector>

namespace adit {

class CompactCloud {
 public:
  CompactCloud() = default;
  // Quantises points (lidar frame) to `step` (m), or to the finest step that reaches the farthest coordinate
  // when that is coarser (32767 steps each way: 5 mm reaches 163 m). Non-finite points are dropped.
  // Decoded points lie within step / 2 of the originals on each axis.
  static CompactCloud encode(const std::vector<Eigen::Vector3f>& points, float step);
  // From stored counts (x, y, z per point): nullopt unless the step is finite and positive and the counts
  // hold whole points.
  static std::optional<CompactCloud> fromCounts(float step, std::vector<std::int16_t> counts);

  std::vector<Eigen::Vector3f> decode() const;
  // No decoded point lies farther than this from the origin (m); 0 for an empty cloud. From the counts alone.
  double maxNorm() const;
  std::size_t size() const { return counts_.size() / 3; }
  bool empty() const { return counts_.empty(); }
  float step() const { return step_; }
  const std::vector<std::int16_t>& counts() const { return counts_; }
  std::size_t bytes() const { return counts_.capacity() * sizeof(std::int16_t); }

 private:
  float step_ = 0.0f;
  std::vector<std::int16_t> counts_;
};

}  // namespace adit
