#include "nodes/feature_node.hpp"

#include "features/feature_extractor.hpp"
#include "msg/convert.hpp"
#include "msg/sweep_codec.hpp"
#include "nodes/sample_buffer.hpp"
#include "nodes/node_config.hpp"

#include <deque>
#include <map>
#include <optional>

namespace adit::nodes {
namespace {

// Deskewing must not depend on process scheduling, so that a live run gives what replay gives: sweep k is
// deskewed with the constant-velocity motion between the odometry poses of sweeps k-2 and k-1 exactly, and
// with the IMU samples up to its own end only. In lockstep those poses are always there when sweep k
// arrives. Live, if ODOM_SCAN of sweep k-1 is still on its way when sweep k arrives, sweep k waits for it
// (or for sweep k+1, whichever comes first: a dead odometry costs one sweep of latency, never a stall).
class FeatureNode : public runtime::Node {
 public:
  explicit FeatureNode(const Config& config)
      : Node("feature"),
        extractor_(featureConfigFrom(config)),
        // IMU older than a sweep plus this margin is of no further use to deskewing.
        imu_(featureNodeConfigTable().read(config).imu_keep_s) {
    const FeatureNodeConfig node = featureNodeConfigTable().read(config);
    max_prior_age_s_ = node.max_prior_age_s;
    map_cloud_voxel_ = node.map_cloud_voxel;
    // LIDAR_POINTS in either form: compact lidar_scan_t or the full-float point_cloud_t of older logs.
    subscribe<msg::SweepMessage>("points", "LIDAR_POINTS", [this](const msg::SweepMessage& m) { onSweep(m); });
    subscribe<adit::imu_t>("imu", "IMU", [this](const adit::imu_t& m) { imu_.add(m); });
    subscribe<adit::odometry_t>("odometry", "ODOM_SCAN", [this](const adit::odometry_t& m) { onOdometry(m); });
    advertise("features", "FEATURES");
  }

  double helperCpuMs() const override { return extractor_.helperCpuMs(); }

 protected:
  // No onRunFolder: nothing to recover (a few poses and IMU samples); a restart only says so on STATUS
  // (Node::useRunFolder).
  void onTimeJump(const std::string& port) override {
    if (port == "points" || port == "odometry") {
      poses_.clear();
      sweeps_.clear();
    }
    if (port == "imu") imu_.clear();
  }
  void onFinish() override { processHeld(); }

 private:
  void onOdometry(const adit::odometry_t& m) {
    odometry_seen_ = true;
    poses_[m.header.utime] = msg::fromMessage(m).pose;
    while (poses_.size() > 8) poses_.erase(poses_.begin());
    if (held_ && !sweeps_.empty() && m.header.utime == sweeps_.back()) processHeld();
  }

  void onSweep(const msg::SweepMessage& m) {
    if (!m.error.empty()) {
      reportError(m.unknown_version ? "unknown_format_version" : "invalid_sweep",
                  "LIDAR_POINTS sweep at utime " + std::to_string(m.header.utime) + ": " + m.error + ": skipped");
      return;
    }
    processHeld();  // its prior never came: go on without it
    const bool prior_pending = odometry_seen_ && !sweeps_.empty() && !poses_.count(sweeps_.back());
    if (prior_pending) {
      held_ = m.scan;  // the only copy of a sweep: the usual path reads the message in place
      count("held_for_prior");
      return;
    }
    process(m.scan);
  }

  void processHeld() {
    if (!held_) return;
    const LidarScan scan = std::move(*held_);
    held_.reset();
    process(scan);
  }

  // Constant velocity between the poses of the two previous sweeps, if both are known and recent enough.
  MotionPrior motionPrior(std::int64_t sweep_utime) const {
    MotionPrior prior;
    if (sweeps_.size() < 2) return prior;
    const auto a = poses_.find(sweeps_[sweeps_.size() - 2]), b = poses_.find(sweeps_.back());
    if (a == poses_.end() || b == poses_.end()) return prior;
    const double age = toSeconds(sweep_utime - b->first);
    const double dt = toSeconds(b->first - a->first);
    if (age <= 0 || age > max_prior_age_s_ || dt <= 0) return prior;
    prior.T_prev_curr = a->second.inverse() * b->second;
    prior.dt_s = dt;
    prior.valid = true;
    return prior;
  }

  void process(const LidarScan& scan) {
    if (scan.points.empty()) reportDrop("empty_scan", "sweep at utime " + std::to_string(scan.utime) + " has no points");
    std::vector<ImuSample> imu = imu_.samples();
    // Only what was measured up to the sweep's end: later samples may or may not have arrived yet.
    while (!imu.empty() && imu.back().utime > scan.utime) imu.pop_back();
    FeatureSet features = extractor_.process(scan, imu, motionPrior(scan.utime), static_cast<float>(map_cloud_voxel_));
    sweeps_.push_back(scan.utime);
    if (sweeps_.size() > 2) sweeps_.pop_front();
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
  double map_cloud_voxel_ = 0.1;
  std::deque<std::int64_t> sweeps_;                 // utimes of the last two sweeps processed
  std::map<std::int64_t, Eigen::Isometry3d> poses_;  // recent ODOM_SCAN poses by sweep utime
  std::optional<LidarScan> held_;                    // a sweep waiting for the previous sweep's pose
  bool odometry_seen_ = false;                       // without an odometry stage, nothing to wait for
};

}  // namespace

std::unique_ptr<runtime::Node> makeFeatureNode(const Config& config) { return std::make_unique<FeatureNode>(config); }

}  // namespace adit::nodes
