#include "nodes/mapper_node.hpp"

#include "core/geometry.hpp"
#include "eval/trajectory_io.hpp"
#include "io/pcd.hpp"
#include "features/preprocess.hpp"
#include "mapping/scan_to_map.hpp"
#include "msg/convert.hpp"
#include "nodes/node_config.hpp"
#include "nodes/products.hpp"

#include <adit/command_t.hpp>
#include <adit/pose_graph_t.hpp>
#include <spdlog/spdlog.h>

#include <filesystem>

namespace adit::nodes {
namespace {

class MapperNode : public runtime::Node, public WritesProducts {
 public:
  explicit MapperNode(const Config& config)
      : Node("mapper"), mapper_(mapperConfigFrom(config)),
        map_voxel_(mapperNodeConfigTable().read(config).map_voxel),
        map_path_(mapperNodeConfigTable().read(config).map_path),
        // ODOM_MAPPED carries the sweep for the loop closer's keyframes, which it thins to 0.2 m itself
        // (loop.keyframe_voxel); keep this at or below that. 0 = forward it whole.
        forward_voxel_(mapperNodeConfigTable().read(config).forward_cloud_voxel) {
    subscribe<adit::odometry_t>("odometry", "ODOM_SCAN", [this](const adit::odometry_t& m) { onOdometry(m); });
    subscribe<adit::pose_graph_t>("graph", "POSE_GRAPH", [this](const adit::pose_graph_t& m) { onGraph(m); },
                                  runtime::InputKind::Events);
    subscribe<adit::command_t>("command", "MAPPER_COMMAND", [this](const adit::command_t& m) { onCommand(m); },
                               runtime::InputKind::Requests);
    advertise("mapped", "ODOM_MAPPED");
  }

  std::vector<std::string> writeProducts(const std::string& out_dir) override {
    namespace fs = std::filesystem;
    const std::string odometry = (fs::path(out_dir) / "odometry.tum").string();
    const std::string trajectory = (fs::path(out_dir) / "trajectory.tum").string();
    const std::string map = (fs::path(out_dir) / "map.pcd").string();
    eval::writeTum(odometry, uncorrected_);
    eval::writeTum(trajectory, corrected_);  // the loop closer, when it runs, rewrites it from its graph
    saveMap(map);
    return {odometry, trajectory, map};
  }

 protected:
  void onFinish() override {
    if (!map_path_.empty()) saveMap(map_path_);
  }

 private:
  void onOdometry(const adit::odometry_t& m) {
    FeatureSet features = msg::fromMessage(m.features);
    const PoseEstimate mapped = mapper_.process(features, msg::fromMessage(m));
    // The loop closer needs the pose, the sweep and the keypoints, not the LOAM sets.
    features.corner_less_sharp.clear();
    features.surf_less_flat.clear();
    if (forward_voxel_ > 0)
      features.cloud.points = features::voxelDownsample(features.cloud.points, static_cast<float>(forward_voxel_));
    if (mapped.flags & PoseEstimate::kRegistrationFailed) count("registration_failed");
    if (mapped.flags & PoseEstimate::kDegenerateTranslation) count("degenerate_translation");
    if (mapped.flags & PoseEstimate::kDegenerateRotation) count("degenerate_rotation");
    adit::odometry_t out = msg::toMessage(mapped, &features);
    splitPose(applied_, out.loop_correction_position, out.loop_correction_orientation);
    publish("mapped", out);
    corrected_.push_back({mapped.utime, mapped.pose});
    uncorrected_.push_back({mapped.utime, applied_.inverse() * mapped.pose});
  }

  // The graph's correction is total (relative to uncorrected poses); apply what is new to us.
  void onGraph(const adit::pose_graph_t& m) {
    const Eigen::Isometry3d total = makePose(m.correction_position, m.correction_orientation);
    mapper_.applyCorrection(total * applied_.inverse());
    applied_ = total;
    count("loop_corrections");
  }

  void onCommand(const adit::command_t& m) {
    if (m.command == "save_map") {
      saveMap(m.argument.empty() ? map_path_ : m.argument);
    } else {
      reportError("unknown_command", "unknown command '" + m.command + "' (known: save_map)");
    }
  }

  void saveMap(const std::string& path) {
    if (path.empty()) {
      reportError("save_failed", "save_map: no path given and mapping.node.map_path is not set");
      return;
    }
    std::vector<LidarPoint> points;
    for (const auto& p : mapper_.globalMap(map_voxel_)) points.push_back({p, 0.0f, 0, 0.0f});
    try {
      io::writePcd(path, points);
      spdlog::info("[mapper] saved map ({} points) to {}", points.size(), path);
    } catch (const std::exception& e) {
      reportError("save_failed", e.what());
    }
  }

  ScanToMapMapper mapper_;
  double map_voxel_;
  std::string map_path_;
  double forward_voxel_;
  Eigen::Isometry3d applied_ = Eigen::Isometry3d::Identity();  // total loop correction applied so far
  Trajectory corrected_, uncorrected_;
};

}  // namespace

std::unique_ptr<runtime::Node> makeMapperNode(const Config& config) { return std::make_unique<MapperNode>(config); }

}  // namespace adit::nodes
