// A keyframe's LinK3D keypoints and descriptors as the loop closer keeps them: positions in the keyframe's lidar
// frame, and of each descriptor only its non-empty bins (a descriptor holds one distance per other keypoint and
// orientation, so with a few dozen keypoints most of its 180 bins are empty), each a distance in whole cm.
// ~100 bytes a keypoint instead of 732; a few kB per 16-beam keyframe next to its ~30 kB cloud.
#pragma once

#include "core/byte_codec.hpp"
#include "core/types.hpp"

#include <cstdint>
#include <memory>
#include <optional>
#include <vector>

namespace adit {

class KeyframeKeypoints {
 public:
  KeyframeKeypoints() = default;
  // Keeps min(keypoints, descriptors) pairs; a non-finite keypoint is dropped with its descriptor, and a bin
  // that is not a finite non-negative distance is stored as empty (0).
  static KeyframeKeypoints encode(const std::vector<Eigen::Vector3f>& keypoints,
                                  const std::vector<LinK3dDescriptor>& descriptors);

  std::size_t size() const { return points_.size(); }
  bool empty() const { return points_.empty(); }
  const std::vector<Eigen::Vector3f>& points() const { return points_; }
  std::vector<LinK3dDescriptor> descriptors() const;  // decoded, metres
  std::size_t bytes() const;

  void put(ByteWriter& w) const;
  // nullopt (and the reader failed) on a count the bytes cannot hold or a non-finite keypoint.
  static std::optional<KeyframeKeypoints> get(ByteReader& r);

 private:
  std::vector<Eigen::Vector3f> points_;
  std::vector<std::uint32_t> end_;    // [i]: one past keypoint i's last bin entry
  std::vector<std::uint8_t> bin_;     // non-empty bins, keypoint by keypoint
  std::vector<std::uint16_t> dist_;   // their distances, cm
};

// Shared and immutable: a loop job's snapshot copies a pointer, not the keypoints; null = none.
using KeyframeKeypointsPtr = std::shared_ptr<const KeyframeKeypoints>;

}  // namespace adit
