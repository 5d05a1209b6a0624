// Drives a stage node the way a process does (a run folder, encoded messages in, a sink collecting what it
// publishes), for tests of live behaviour without LCM.
#pragma once

#include "../io/temp_dir.hpp"
#include "msg/encode.hpp"
#include "runtime/node.hpp"

#include <filesystem>
#include <map>
#include <string>
#include <vector>

namespace adit::test {

// A fresh folder under the system temp dir, removed at scope exit (the io tests' helper).
using TempFolder = io::test::TempDir;

struct Collector : runtime::Sink {
  void publish(const std::string& channel, const runtime::Bytes& data, std::int64_t) override {
    messages[channel].push_back(data);
  }
  std::map<std::string, std::vector<runtime::Bytes>> messages;
};

inline runtime::RunFolder liveFolder(const std::string& dir, const std::string& run_id = "run-1", int restarts = 0) {
  runtime::RunFolder f;
  f.dir = dir;
  f.run_id = run_id;
  f.given = true;
  f.live = true;
  f.restart_count = restarts;
  return f;
}

template <class Msg>
void deliver(runtime::Node& node, const std::string& channel, const Msg& m, runtime::Sink& sink) {
  const runtime::Bytes bytes = msg::encode(m);
  node.deliver(channel, bytes.data(), bytes.size(), sink);
}

inline std::int64_t counter(const runtime::Node& node, const std::string& name) {
  const auto& c = node.health().counters;
  const auto it = c.find(name);
  return it == c.end() ? 0 : it->second;
}

}  // namespace adit::test

#include "core/types.hpp"
#include "msg/convert.hpp"

#include <cmath>

namespace adit::test {

// A sweep of a 4 m wide, 3 m high corridor along x with ribs every 2 m, seen from x = along (lidar frame:
// the corridor's frame shifted by -along), as the mapper forwards it on ODOM_MAPPED / odometry on ODOM_SCAN.
inline FeatureSet corridorSweep(std::int64_t utime, double along) {
  FeatureSet f;
  f.utime = utime;
  f.cloud.utime = utime;
  for (double x = -20; x <= 20; x += 0.25) {
    const double wx = x + along;
    const double rib = std::fmod(std::abs(wx), 2.0) < 0.25 ? 0.3 : 0.0;
    for (double z = -1.0; z <= 2.0; z += 0.25) {
      f.cloud.points.push_back({Eigen::Vector3f(float(x), float(2.0 - rib), float(z)), 0.f, 0, 0.f});
      f.cloud.points.push_back({Eigen::Vector3f(float(x), float(-2.0 + rib), float(z)), 0.f, 1, 0.f});
    }
    for (double y = -2.0; y <= 2.0; y += 0.25) {
      f.cloud.points.push_back({Eigen::Vector3f(float(x), float(y), -1.0f), 0.f, 2, 0.f});
      f.cloud.points.push_back({Eigen::Vector3f(float(x), float(y), float(2.0 - rib)), 0.f, 3, 0.f});
    }
  }
  for (const LidarPoint& p : f.cloud.points) {
    if (std::abs(p.p.z() + 1.0f) < 0.01f || std::abs(p.p.y()) > 1.9f) f.surf_less_flat.push_back(p);
    else f.corner_less_sharp.push_back(p);
  }
  f.surf_flat = f.surf_less_flat;
  f.corner_sharp = f.corner_less_sharp;
  return f;
}

// ODOM_MAPPED for sweep k of a drive along the corridor at `step` m per sweep (10 Hz).
inline adit::odometry_t mappedMessage(int k, double step = 1.0) {
  PoseEstimate pose;
  pose.utime = 1'000'000 + std::int64_t{k} * 100'000;
  pose.pose.translation() = Eigen::Vector3d(k * step, 0, 0);
  const FeatureSet f = corridorSweep(pose.utime, k * step);
  adit::odometry_t m = msg::toMessage(pose, &f);
  m.header.seq = k;
  return m;
}

}  // namespace adit::test
