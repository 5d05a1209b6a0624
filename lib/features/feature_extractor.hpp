// The feature stage: raw sweep (+ IMU, + motion prior) -> FeatureSet. Pure: output depends only on inputs.
#pragma once

#include "core/types.hpp"
#include "features/deskew.hpp"
#include "features/feature_config.hpp"

#include <utility>
#include <vector>

namespace adit {

class FeatureExtractor {
 public:
  explicit FeatureExtractor(FeatureConfig cfg) : cfg_(std::move(cfg)) {}

  // preprocess -> deskew -> smoothness -> LOAM sets + LinK3D keypoints and descriptors.
  // imu: samples covering the sweep [utime - sweep_duration, utime] (may be empty);
  // motion: constant-velocity prior from odometry (valid = false if none).
  // Degenerate input (no points, empty rings, few keypoints) gives a valid FeatureSet with flags set.
  FeatureSet process(const LidarScan& scan, const std::vector<ImuSample>& imu, const MotionPrior& motion) const;

  const FeatureConfig& config() const { return cfg_; }

 private:
  FeatureConfig cfg_;
};

}  // namespace adit
