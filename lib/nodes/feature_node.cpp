#include "nodes/feature_node.hpp"

#include "features/feature_extractor.hpp"
#include "features/preprocess.hpp"
#include "msg/convert.hpp"
#include "msg/sweep_codec.hpp"
#include "nodes/imu_buffer.hpp"

#include <deque>

namespace adit::nodes {
namespace {

class FeatureNode : public runtime::Node {
 public:
  explicit FeatureNode(const Config& config)
      : Node("feature"),
        extractor_(featureConfigFrom(config)),
        // IMU older than a sweep plus this margin is of no further use to deskewing.
        imu_(config.get<double>("features.node.imu_keep_s", 0.5)) {
    // An odometry pose older than this (s) before a sweep is too stale to predict its motion.
    max_prior_age_s_ = config.get<double>("features.node.max_prior_age_s", 0.3);
    // FEATURES carries the sweep only thinned to this voxel (m): what the mapper's global map (0.1 m) and,
    // thinned again, the loop closer's keyframes need. 0 = the whole preprocessed sweep (5x the bytes).
    map_cloud_voxel_ = config.get<double>("features.node.map_cloud_voxel", 0.1);
    // LIDAR_POINTS in either form: compact lidar_scan_t or the full-float point_cloud_t of older logs.
    subscribe<msg::SweepMessage>("points", "LIDAR_POINTS", [this](const msg::SweepMessage& m) { onSweep(m); });
    subscribe<adit::imu_t>("imu", "IMU", [this](const adit::imu_t& m) { imu_.add(m); });
    subscribe<adit::odometry_t>("odometry", "ODOM_SCAN", [this](const adit::odometry_t& m) { onOdometry(m); });
    advertise("features", "FEATURES");
  }

 protected:
  void onTimeJump(const std::string& port) override {
    if (port == "points" || port == "odometry") poses_.clear();
    if (port == "imu") imu_.clear();
  }

 private:
  void onOdometry(const adit::odometry_t& m) {
    poses_.push_back({m.header.utime, msg::fromMessage(m).pose});
    if (poses_.size() > 2) poses_.pop_front();
  }

  // Constant velocity: the motion between the last two odometry poses, if they are recent enough.
  MotionPrior motionPrior(std::int64_t sweep_utime) const {
    MotionPrior prior;
    if (poses_.size() < 2) return prior;
    const double age = toSeconds(sweep_utime - poses_.back().utime);
    const double dt = toSeconds(poses_.back().utime - poses_.front().utime);
    if (age <= 0 || age > max_prior_age_s_ || dt <= 0) return prior;
    prior.T_prev_curr = poses_.front().pose.inverse() * poses_.back().pose;
    prior.dt_s = dt;
    prior.valid = true;
    return prior;
  }

  void onSweep(const msg::SweepMessage& m) {
    if (!m.error.empty()) {
      reportError(m.unknown_version ? "unknown_format_version" : "invalid_sweep",
                  "LIDAR_POINTS sweep at utime " + std::to_string(m.header.utime) + ": " + m.error + ": skipped");
      return;
    }
    const LidarScan& scan = m.scan;
    if (scan.points.empty()) reportDrop("empty_scan", "sweep at utime " + std::to_string(scan.utime) + " has no points");
    const std::vector<ImuSample> imu = imu_.samples();
    FeatureSet features = extractor_.process(scan, imu, motionPrior(scan.utime));
    count("points_in", features.points_in);
    count("removed_invalid", features.removed_invalid);
    count("removed_range", features.removed_range);
    count("removed_outlier", features.removed_outlier);
    if (features.flags & FeatureSet::kFewKeypoints) count("few_keypoints");
    if (features.flags & FeatureSet::kEmptyRing) count("empty_ring");
    if (map_cloud_voxel_ > 0)
      features.cloud.points = features::voxelDownsample(features.cloud.points, static_cast<float>(map_cloud_voxel_));
    adit::features_t out = msg::toMessage(features);
    publish("features", out);
  }

  FeatureExtractor extractor_;
  ImuBuffer imu_;
  double max_prior_age_s_ = 0.3;
  double map_cloud_voxel_ = 0.1;
  std::deque<StampedPose> poses_;
};

}  // namespace

std::unique_ptr<runtime::Node> makeFeatureNode(const Config& config) { return std::make_unique<FeatureNode>(config); }

}  // namespace adit::nodes
