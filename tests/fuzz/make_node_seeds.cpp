// Writes the node_messages seed corpus: a few synthetic 16-beam sweeps of a box-shaped roadway and IMU
// samples, run through all four pipeline nodes in lockstep; every message a node received is kept, per
// node, in the harness's input format. With a second folder, also the view_messages seed: what adit view
// would have received of the same run (sweeps, mapped poses, graph, map updates) with ground truth, a loop
// and a STATUS. Build and run (from the repository root) when the messages change:
//   cmake --build build --target fuzz_make_node_seeds
//   build/bin/fuzz_make_node_seeds tests/fuzz/corpus/node_messages tests/fuzz/corpus/view_messages
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <map>
#include <string>
#include <vector>

#include <adit/status_t.hpp>

#include "msg/convert.hpp"
#include "msg/encode.hpp"
#include "nodes/registry.hpp"
#include "runtime/lockstep.hpp"

namespace {

// Range from the origin along `dir` to the walls of a 40 x 5 x 4 m box around (x, 0, 0).
float boxRange(const Eigen::Vector3f& dir, float x) {
  float best = 1e9f;
  const float lo[3] = {-20.0f - x, -2.5f, -1.5f}, hi[3] = {20.0f - x, 2.5f, 2.5f};
  for (int a = 0; a < 3; ++a) {
    if (std::fabs(dir[a]) < 1e-6f) continue;
    for (float wall : {lo[a], hi[a]}) {
      const float t = wall / dir[a];
      if (t > 0.0f && t < best) best = t;
    }
  }
  return best;
}

adit::LidarScan sweep(int k) {
  adit::LidarScan scan;
  scan.utime = 1000000 + 100000LL * k;
  scan.seq = k;
  scan.sensor = "vlp16";
  scan.num_beams = 16;
  scan.has_ring = scan.has_time = true;
  const float x = 0.05f * static_cast<float>(k);
  for (int ring = 0; ring < 16; ++ring)
    for (int i = 0; i < 90; ++i) {
      const float el = (-15.0f + 2.0f * ring) * static_cast<float>(M_PI) / 180.0f;
      const float az = 2.0f * static_cast<float>(M_PI) * (static_cast<float>(i) + 0.37f * static_cast<float>(ring)) / 90.0f;
      const Eigen::Vector3f dir(std::cos(el) * std::cos(az), std::cos(el) * std::sin(az), std::sin(el));
      adit::LidarPoint p;
      p.p = dir * boxRange(dir, x);
      p.ring = static_cast<std::uint16_t>(ring);
      p.intensity = static_cast<float>((i * 7 + ring) % 100);
      p.dt = -0.1f * static_cast<float>(89 - i) / 90.0f;
      scan.points.push_back(p);
    }
  return scan;
}

}  // namespace

int main(int argc, char** argv) {
  if (argc != 2 && argc != 3) return 2;
  const std::string out_dir = argv[1];
  const auto& names = adit::nodes::pipelineNodeNames();
  std::vector<std::unique_ptr<adit::runtime::Node>> nodes;
  adit::runtime::LockstepBus bus;
  for (const auto& name : names) nodes.push_back(adit::nodes::makeNode(name, adit::Config{}));
  for (auto& n : nodes) bus.add(*n);
  // Per node: the harness input (node byte, then [channel byte][uint16 size][bytes] per message).
  std::vector<std::string> inputs(nodes.size());
  for (std::size_t i = 0; i < nodes.size(); ++i) inputs[i] = std::string(1, static_cast<char>(i));
  const auto record = [&](const std::string& channel, const adit::runtime::Bytes& data) {
    for (std::size_t i = 0; i < nodes.size(); ++i) {
      const auto channels = nodes[i]->inputChannels();
      for (std::size_t c = 0; c < channels.size(); ++c) {
        if (channels[c] != channel || data.size() > 65535 || inputs[i].size() > 60000) continue;
        inputs[i] += static_cast<char>(c);
        inputs[i] += static_cast<char>(data.size() & 0xFF);
        inputs[i] += static_cast<char>(data.size() >> 8);
        inputs[i].append(data.begin(), data.end());
      }
    }
  };
  // The view harness's input: [channel byte][uint16 size][bytes], channels as fuzz_view_messages.cpp lists them.
  const std::vector<std::string> view_channels{"LIDAR_POINTS", "ODOM_MAPPED", "GROUND_TRUTH", "POSE_GRAPH",
                                               "LOOP_CLOSURE", "MAP_UPDATE",  "STATUS_mapper"};
  std::string view_input;
  const auto recordView = [&](const std::string& channel, const std::vector<std::uint8_t>& data) {
    const auto c = std::find(view_channels.begin(), view_channels.end(), channel);
    if (c == view_channels.end() || data.size() > 65535 || view_input.size() + data.size() > 90000) return;
    view_input += static_cast<char>(c - view_channels.begin());
    view_input += static_cast<char>(data.size() & 0xFF);
    view_input += static_cast<char>(data.size() >> 8);
    view_input.append(data.begin(), data.end());
  };
  bus.observe([&](const std::string& channel, const adit::runtime::Bytes& data, std::int64_t) {
    record(channel, data);
    recordView(channel, data);
  });
  for (int k = 0; k < 6; ++k) {
    for (int j = 0; j < 10; ++j) {
      adit::ImuSample imu;
      imu.utime = 1000000 + 100000LL * k - 90000 + 10000LL * j;
      imu.gyro = Eigen::Vector3d(0.001, -0.002, 0.01);
      imu.accel = Eigen::Vector3d(0.05, 0.0, 9.81);
      adit::imu_t m = adit::msg::toMessage(imu);
      m.header.seq = 10 * k + j;
      const auto bytes = adit::msg::encode(m);
      record("IMU", bytes);
      bus.inject("IMU", bytes, imu.utime);
    }
    const adit::point_cloud_t cloud = adit::msg::toMessage(sweep(k));
    const auto bytes = adit::msg::encode(cloud);
    record("LIDAR_POINTS", bytes);
    if (k % 3 == 0) recordView("LIDAR_POINTS", bytes);  // two sweeps: the seed stays small
    bus.inject("LIDAR_POINTS", bytes, cloud.header.utime);
    adit::PoseEstimate truth;
    truth.utime = cloud.header.utime;
    truth.pose.translation().x() = 0.05 * k;
    recordView("GROUND_TRUTH", adit::msg::encode(adit::msg::toMessage(truth, nullptr)));
  }
  bus.finish();
  adit::LoopConstraint loop;
  loop.query_index = 5;
  loop.match_index = 0;
  loop.query_utime = 1500000;
  loop.match_utime = 1000000;
  recordView("LOOP_CLOSURE", adit::msg::encode(adit::msg::toMessage(loop, 1500000)));
  adit::status_t status{};
  status.process = "mapper";
  status.state = "running";
  status.inputs = 6;
  status.num_counters = 1;
  status.counter_names = {"lost_input"};
  status.counter_values = {2};
  recordView("STATUS_mapper", adit::msg::encode(status));
  if (argc == 3) {
    const std::string path = std::string(argv[2]) + "/run";
    std::FILE* f = std::fopen(path.c_str(), "wb");
    if (!f) return 1;
    std::fwrite(view_input.data(), 1, view_input.size(), f);
    std::fclose(f);
    std::printf("%s: %zu bytes\n", path.c_str(), view_input.size());
  }
  for (std::size_t i = 0; i < nodes.size(); ++i) {
    const std::string path = out_dir + "/" + names[i];
    std::FILE* f = std::fopen(path.c_str(), "wb");
    if (!f) return 1;
    std::fwrite(inputs[i].data(), 1, inputs[i].size(), f);
    std::fclose(f);
    std::printf("%s: %zu bytes\n", path.c_str(), inputs[i].size());
  }
  return 0;
}
