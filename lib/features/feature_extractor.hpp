// The feature stage: raw sweep (+ IMU, + motion prior) -> FeatureSet. Pure: output depends only on inputs.
#pragma once

#include "core/types.hpp"
#include "features/deskew.hpp"
#include "features/feature_config.hpp"

#include <memory>
#include <utility>
#include <vector>

namespace adit {

class ChunkPool;  // core/chunk_pool.hpp

class FeatureExtractor {
 public:
  explicit FeatureExtractor(FeatureConfig cfg);

  // preprocess -> deskew -> smoothness -> LOAM sets + LinK3D keypoints and descriptors.
  // imu: samples covering the sweep [utime - sweep_duration, utime] (may be empty);
  // motion: constant-velocity prior from odometry (valid = false if none).
  // cloud_voxel > 0: FeatureSet::cloud is the deskewed sweep thinned to this voxel (centroids,
  // features::voxelDownsample), what FEATURES carries for the maps; 0: the whole deskewed sweep.
  // Degenerate input (no points, empty rings, few keypoints) gives a valid FeatureSet with flags set.
  // The same result for any features.threads; calls on one extractor from several threads take turns.
  FeatureSet process(const LidarScan& scan, const std::vector<ImuSample>& imu, const MotionPrior& motion,
                     float cloud_voxel = 0.0f) const;

  const FeatureConfig& config() const { return cfg_; }
  // CPU time (ms, monitoring only) of the features.threads beside the caller's: negative without them.
  double helperCpuMs() const;

 private:
  FeatureConfig cfg_;
  std::shared_ptr<ChunkPool> pool_;  // features.threads > 1
};

}  // namespace adit
