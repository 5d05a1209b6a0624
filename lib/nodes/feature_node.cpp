#include "nodes/feature_node.hpp"

#include "features/feature_extractor.hpp"
#include "msg/convert.hpp"
#include "nodes/imu_buffer.hpp"
#include "nodes/node_config.hpp"

#include <deque>

namespace adit::nodes {
namespace {

class FeatureNode : public runtime::Node {
 public:
  explicit FeatureNode(const Config& config)
      : Node("feature"),
        extractor_(featureConfigFrom(config)),
        // IMU older than a sweep plus this margin is of no further use to deskewing.
        imu_(featureNodeConfigTable().read(config).imu_keep_s) {
    max_prior_age_s_ = featureNodeConfigTable().read(config).max_prior_age_s;
    subscribe<adit::point_cloud_t>("points", "LIDAR_POINTS", [this](const adit::point_cloud_t& m) { onSweep(m); });
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

  void onSweep(const adit::point_cloud_t& m) {
    const LidarScan scan = msg::fromMessage(m);
    if (scan.points.empty()) reportDrop("empty_scan", "sweep at utime " + std::to_string(scan.utime) + " has no points");
    const std::vector<ImuSample> imu = imu_.samples();
    const FeatureSet features = extractor_.process(scan, imu, motionPrior(scan.utime));
    count("points_in", features.points_in);
    count("removed_invalid", features.removed_invalid);
    count("removed_range", features.removed_range);
    count("removed_outlier", features.removed_outlier);
    if (features.flags & FeatureSet::kFewKeypoints) count("few_keypoints");
    if (features.flags & FeatureSet::kEmptyRing) count("empty_ring");
    adit::features_t out = msg::toMessage(features);
    publish("features", out);
  }

  FeatureExtractor extractor_;
  ImuBuffer imu_;
  double max_prior_age_s_ = 0.3;
  std::deque<StampedPose> poses_;
};

}  // namespace

std::unique_ptr<runtime::Node> makeFeatureNode(const Config& config) { return std::make_unique<FeatureNode>(config); }

}  // namespace adit::nodes
