#include "nodes/loop_closer_node.hpp"

#include "core/geometry.hpp"
#include "eval/trajectory_io.hpp"
#include "io/pcd.hpp"
#include "loop/loop_closer.hpp"
#include "loop/pose_graph.hpp"
#include "msg/convert.hpp"
#include "nodes/node_config.hpp"
#include "nodes/products.hpp"

#include <adit/pose_graph_t.hpp>

#include <filesystem>

namespace adit::nodes {
namespace {

class LoopCloserNode : public runtime::Node, public WritesProducts {
 public:
  explicit LoopCloserNode(const Config& config)
      : Node("loop_closer"), closer_(loopCloserConfigFrom(config)),
        map_voxel_(loopCloserNodeConfigTable().read(config).map_voxel) {
    subscribe<adit::odometry_t>("mapped", "ODOM_MAPPED", [this](const adit::odometry_t& m) { onMapped(m); });
    advertise("loop", "LOOP_CLOSURE");
    advertise("graph", "POSE_GRAPH");
  }

  std::vector<std::string> writeProducts(const std::string& out_dir) override {
    namespace fs = std::filesystem;
    const std::string trajectory = (fs::path(out_dir) / "trajectory.tum").string();
    const std::string map = (fs::path(out_dir) / "map.pcd").string();
    const std::string graph = (fs::path(out_dir) / "pose_graph.g2o").string();
    eval::writeTum(trajectory, closer_.correctedTrajectory(uncorrected_));
    std::vector<LidarPoint> points;
    for (const auto& p : closer_.correctedMap(map_voxel_)) points.push_back({p, 0.0f, 0, 0.0f});
    io::writePcd(map, points);
    saveG2o(closer_.graph(), graph);
    return {trajectory, map, graph};
  }

 private:
  void onMapped(const adit::odometry_t& m) {
    PoseEstimate mapped = msg::fromMessage(m);
    // The graph is built on uncorrected poses: undo the correction the mapper had already applied.
    mapped.pose = makePose(m.loop_correction_position, m.loop_correction_orientation).inverse() * mapped.pose;
    const LidarScan cloud = msg::fromMessage(m.features.cloud);
    uncorrected_.push_back({mapped.utime, mapped.pose});
    const LoopCloser::Result result = closer_.process(mapped, cloud);
    for (const LoopConstraint& loop : result.loops) {
      adit::loop_closure_t out = msg::toMessage(loop, mapped.utime);
      publish("loop", out);
    }
    if (result.graph_updated) publishGraph(mapped.utime, result);
    const LoopCloserStats& s = closer_.stats();
    setCount("keyframes", s.keyframes);
    setCount("loop_candidates", s.candidates);
    setCount("loops_accepted", s.accepted);
    setCount("rejected_fitness", s.rejected_fitness);
    setCount("rejected_degenerate", s.rejected_degenerate);
    setCount("rejected_odometry_gate", s.rejected_odometry);
    setCount("rejected_pairwise", s.rejected_pairwise);
    setCount("invalid_sweeps", s.invalid_sweeps);
  }

  void publishGraph(std::int64_t utime, const LoopCloser::Result& result) {
    adit::pose_graph_t g;
    g.header = msg::makeHeader(utime, "world");
    g.num_nodes = static_cast<std::int32_t>(result.corrected_keyframes.size());
    for (const StampedPose& k : result.corrected_keyframes) {
      g.node_utime.push_back(k.utime);
      std::vector<double> position(3), orientation(4);
      splitPose(k.pose, position.data(), orientation.data());
      g.position.push_back(position);
      g.orientation.push_back(orientation);
    }
    splitPose(result.T_corrected_uncorrected, g.correction_position, g.correction_orientation);
    g.num_loops = static_cast<std::int32_t>(closer_.acceptedLoops().size());
    g.newest_loop = msg::toMessage(result.loop.value_or(LoopConstraint{}), utime);
    publish("graph", g);
  }

  LoopCloser closer_;
  double map_voxel_;
  Trajectory uncorrected_;
};

}  // namespace

std::unique_ptr<runtime::Node> makeLoopCloserNode(const Config& config) {
  return std::make_unique<LoopCloserNode>(config);
}

}  // namespace adit::nodes
