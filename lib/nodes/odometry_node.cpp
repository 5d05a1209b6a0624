#include "nodes/odometry_node.hpp"

#include "features/preprocess.hpp"
#include "msg/convert.hpp"
#include "nodes/imu_buffer.hpp"
#include "nodes/node_config.hpp"
#include "odometry/initial_guess.hpp"
#include "odometry/scan_to_scan.hpp"

#include <deque>
#include <optional>

namespace adit::nodes {
namespace {

class OdometryNode : public runtime::Node {
 public:
  explicit OdometryNode(const Config& config)
      : Node("odometry"),
        odometry_(scanToScanConfigFrom(config)),
        guess_config_(initialGuessConfigFrom(config)),
        imu_(odometryNodeConfigTable().read(config).imu_keep_s) {
    // The sweep forwarded on ODOM_SCAN feeds only the mapper's global map (itself at 0.1 m): thin it to
    // that resolution so the bus and the logs carry a third of the bytes. 0 = forward it whole.
    forward_voxel_ = odometryNodeConfigTable().read(config).forward_cloud_voxel;
    subscribe<adit::features_t>("features", "FEATURES", [this](const adit::features_t& m) { onFeatures(m); });
    subscribe<adit::imu_t>("imu", "IMU", [this](const adit::imu_t& m) { imu_.add(m); });
    advertise("odometry", "ODOM_SCAN");
  }

 protected:
  void onTimeJump(const std::string& port) override {
    if (port == "features") {
      odometry_.reset();
      previous_.reset();
    }
    if (port == "imu") imu_.clear();
  }

 private:
  void onFeatures(const adit::features_t& m) {
    FeatureSet features = msg::fromMessage(m);
    const std::vector<ImuSample> imu = imu_.samples();
    const InitialGuess guess = initialGuess(previous_ ? &*previous_ : nullptr, features,
                                            odometry_.predictMotion(features.utime), imu, guess_config_);
    count("link3d_matches", guess.link3d_matches);
    if (guess.flags & PoseEstimate::kSeededByLinK3d) count("seeded_by_link3d");
    if (guess.flags & PoseEstimate::kSeededByImu) count("seeded_by_imu");
    const PoseEstimate pose = odometry_.process(features, guess.T_prev_curr, guess.flags);
    if (pose.flags & PoseEstimate::kRegistrationFailed) count("registration_failed");
    if (pose.flags & PoseEstimate::kDegenerateTranslation) count("degenerate_translation");
    previous_ = features;
    // Downstream needs neither the odometry-only sets nor the full-density sweep.
    features.corner_sharp.clear();
    features.surf_flat.clear();
    if (forward_voxel_ > 0)
      features.cloud.points = features::voxelDownsample(features.cloud.points, static_cast<float>(forward_voxel_));
    adit::odometry_t out = msg::toMessage(pose, &features);
    publish("odometry", out);
  }

  ScanToScanOdometry odometry_;
  InitialGuessConfig guess_config_;
  ImuBuffer imu_;
  double forward_voxel_ = 0.1;
  std::optional<FeatureSet> previous_;
};

}  // namespace

std::unique_ptr<runtime::Node> makeOdometryNode(const Config& config) { return std::make_unique<OdometryNode>(config); }

}  // namespace adit::nodes
