#include "recorded_run.hpp"

#include "core/geometry.hpp"
#include "msg/convert.hpp"
#include "msg/encode.hpp"
#include "map/map_bundle.hpp"
#include "msg/sweep_codec.hpp"
#include "nodes/products.hpp"
#include "nodes/registry.hpp"
#include "runtime/lockstep.hpp"
#include "sources/sim_source.hpp"

#include <adit/command_t.hpp>
#include <adit/odometry_t.hpp>
#include <adit/pose_graph_t.hpp>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <memory>
#include <stdexcept>
#include <unistd.h>

namespace adit::mutation {
namespace {

// What the loop closer publishes after a loop: every keyframe's corrected pose and the correction (here a
// small one, 4 cm and 0.3 deg, as after a lap), for the keyframes mapped so far (one a second).
adit::pose_graph_t poseGraph(const std::vector<adit::odometry_t>& keyframes, std::int64_t utime) {
  adit::pose_graph_t g;
  g.header = msg::makeHeader(utime, "world");
  Eigen::Isometry3d correction = Eigen::Isometry3d::Identity();
  correction.translate(Eigen::Vector3d(0.03, -0.02, 0.01));
  correction.rotate(Eigen::AngleAxisd(0.005, Eigen::Vector3d::UnitZ()));
  for (const adit::odometry_t& k : keyframes) {
    const Eigen::Isometry3d pose = correction * makePose(k.position, k.orientation);
    std::vector<double> p(3), q(4);
    splitPose(pose, p.data(), q.data());
    g.node_utime.push_back(k.header.utime);
    g.position.push_back(p);
    g.orientation.push_back(q);
  }
  g.num_nodes = static_cast<std::int32_t>(keyframes.size());
  splitPose(correction, g.correction_position, g.correction_orientation);
  g.num_loops = 1;
  g.newest_loop.header = msg::makeHeader(utime, "world");
  g.newest_loop.relative_orientation[0] = 1.0;
  return g;
}

}  // namespace

RecordedRun recordRun(const Config& config, double seconds, int seed) {
  sim::SimConfig sim = sim::simConfigFrom(config, "roadway-loop", static_cast<std::uint64_t>(seed));
  sim.sensor = "vlp16";
  sim.duration_s = seconds;
  sources::SimChannels channels;
  channels.ground_truth = "";
  sources::SimSource source(sim, channels);

  std::vector<std::unique_ptr<runtime::Node>> nodes;
  runtime::LockstepBus bus;
  for (const auto& name : nodes::pipelineNodeNames()) nodes.push_back(nodes::makeNode(name, config));
  for (auto& n : nodes) bus.add(*n);
  RecordedRun run;
  std::vector<adit::odometry_t> keyframes;
  std::int64_t last_keyframe = -1, graph_seq = 0, command_seq = 0, reloc_seq = 0;
  bus.observe([&](const std::string& channel, const runtime::Bytes& data, std::int64_t utime) {
    run.events.push_back({channel, data, utime});
    if (channel != "ODOM_MAPPED") return;
    adit::odometry_t m;
    if (m.decode(data.data(), 0, static_cast<int>(data.size())) < 0) throw std::runtime_error("ODOM_MAPPED undecodable");
    if (last_keyframe >= 0 && utime - last_keyframe < 1'000'000) return;
    last_keyframe = utime;
    keyframes.push_back(m);
    adit::pose_graph_t g = poseGraph(keyframes, utime);
    g.header.seq = graph_seq++;
    run.events.push_back({"POSE_GRAPH", msg::encode(g), utime});
    if (keyframes.size() % 2 == 0) {
      adit::command_t c{};
      c.header = msg::makeHeader(utime, "");
      c.header.seq = command_seq++;
      c.command = "save_map";
      c.argument = "snapshot";
      run.events.push_back({"MAPPER_COMMAND", msg::encode(c), utime});
    }
    if (keyframes.size() % 2 == 1) {  // the operator's guess of where the robot is: here, 0.3 m and 4 deg off
      const Eigen::Isometry3d pose = makePose(m.position, m.orientation);
      const Eigen::Vector3d x = pose.linear().col(0);
      adit::command_t c{};
      c.header = msg::makeHeader(utime, "");
      c.header.seq = reloc_seq++;
      c.command = "set_pose";
      c.argument = std::to_string(pose.translation().x() + 0.3) + " " + std::to_string(pose.translation().y()) + " " +
                   std::to_string(pose.translation().z()) + " " +
                   std::to_string(std::atan2(x.y(), x.x()) * 180.0 / 3.14159265358979323846 + 4.0);
      run.events.push_back({"RELOC_COMMAND", msg::encode(c), utime});
    }
  });
  runtime::OutgoingMessage m;
  while (source.next(m)) {
    if (m.channel == "LIDAR_POINTS") {
      msg::SweepMessage sweep;
      if (sweep.decode(m.data.data(), 0, static_cast<int>(m.data.size())) < 0 || !sweep.error.empty())
        throw std::runtime_error("simulated sweep undecodable");
      adit::point_cloud_t full = msg::toMessage(sweep.scan);
      full.header.seq = sweep.header.seq;
      run.full_sweeps.push_back({m.channel, msg::encode(full), m.utime});
    }
    run.events.push_back({m.channel, m.data, m.utime});
    bus.inject(m.channel, m.data, m.utime);
  }
  bus.finish();
  const auto& names = nodes::pipelineNodeNames();
  const auto loop_closer = std::find(names.begin(), names.end(), "loop_closer") - names.begin();
  auto* owner = dynamic_cast<nodes::WritesBundle*>(nodes.at(static_cast<std::size_t>(loop_closer)).get());
  if (!owner) throw std::runtime_error("the loop closer does not write map bundles");
  run.bundle_dir = (std::filesystem::temp_directory_path() /
                    ("adit_mutation_bundle_" + std::to_string(::getpid()) + "_" + std::to_string(seconds))).string();
  writeMapBundle(owner->mapBundle(), run.bundle_dir);
  return run;
}

}  // namespace adit::mutation
