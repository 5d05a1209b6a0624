// The run model a viewer and the MCAP export build from a run's messages: trajectories before and after
// loop correction, loops between corrected keyframes, the map's submaps re-placed when a loop moves them,
// STATUS rows; malformed and unexpected messages counted and skipped. Then the same messages through the
// export: every topic written, loops and STATUS included.
#include "foxglove/mcap_sink.hpp"
#include "view/run_decoder.hpp"

#include "core/geometry.hpp"
#include "mcap_walk.hpp"
#include "msg/encode.hpp"
#include "msg/type_name.hpp"

#include <adit/imu_t.hpp>
#include <adit/loop_closure_t.hpp>
#include <adit/map_update_t.hpp>
#include <adit/odometry_t.hpp>
#include <adit/odometry_v1_t.hpp>
#include <adit/pose_graph_t.hpp>
#include <adit/status_t.hpp>
#include <gtest/gtest.h>

#include <sstream>

namespace {

using adit::view::RunDecoder;
using adit::view::RunModel;

Eigen::Isometry3d poseXYZYaw(double x, double y, double z, double yaw) {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.translation() = Eigen::Vector3d(x, y, z);
  T.linear() = Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  return T;
}

void setHeader(adit::header_t& h, std::int64_t utime) {
  h.utime = utime;
  h.seq = 0;
  h.frame_id = "world";
}

adit::odometry_t odometry(std::int64_t utime, const Eigen::Isometry3d& pose, const Eigen::Isometry3d& correction) {
  adit::odometry_t m{};
  setHeader(m.header, utime);
  adit::splitPose(pose, m.position, m.orientation);
  adit::splitPose(correction, m.loop_correction_position, m.loop_correction_orientation);
  for (auto* set : {&m.corners, &m.surfaces, &m.cloud}) set->scale = 0.001f;
  return m;
}

adit::pose_graph_t poseGraph(std::int64_t utime, const std::vector<std::pair<std::int64_t, Eigen::Isometry3d>>& nodes,
                             std::int64_t loop_query, std::int64_t loop_match) {
  adit::pose_graph_t m{};
  setHeader(m.header, utime);
  m.num_nodes = static_cast<int>(nodes.size());
  for (const auto& [t, pose] : nodes) {
    m.node_utime.push_back(t);
    std::vector<double> p(3), q(4);
    adit::splitPose(pose, p.data(), q.data());
    m.position.push_back(p);
    m.orientation.push_back(q);
  }
  adit::splitPose(Eigen::Isometry3d::Identity(), m.correction_position, m.correction_orientation);
  m.num_loops = 1;
  m.newest_loop.query_utime = loop_query;
  m.newest_loop.match_utime = loop_match;
  setHeader(m.newest_loop.header, loop_query);
  m.newest_loop.relative_orientation[0] = 1;
  return m;
}

adit::map_update_t mapUpdate(std::int64_t utime, const Eigen::Isometry3d& pose, bool as_new) {
  adit::map_update_t m{};
  setHeader(m.header, utime);
  double p[3], q[4];
  adit::splitPose(pose, p, q);
  if (as_new) {
    adit::map_submap_t s{};
    s.id = 0;
    s.utime = utime;
    std::copy(p, p + 3, s.position);
    std::copy(q, q + 4, s.orientation);
    s.points = {{1, 0, 0}, {0, 2, 0}};
    s.num_points = 2;
    m.new_submaps.push_back(s);
    m.num_new = 1;
  } else {
    m.moved_id = {0};
    m.moved_position = {{p[0], p[1], p[2]}};
    m.moved_orientation = {{q[0], q[1], q[2], q[3]}};
    m.num_moved = 1;
  }
  m.num_submaps = 1;
  return m;
}

adit::status_t status(const std::string& process, std::int64_t wall_utime) {
  adit::status_t m{};
  setHeader(m.header, wall_utime);
  m.process = process;
  m.state = "behind";
  m.inputs = 42;
  m.busy_fraction = 0.95f;
  m.counter_names = {"decode_error"};
  m.counter_values = {3};
  m.num_counters = 1;
  return m;
}

struct Event {
  std::string channel;
  std::vector<std::uint8_t> data;
  std::int64_t utime;
};

// Three sweeps 1 m apart; the loop closer then corrects keyframe 2 by +0.5 m in y, which moves sweep 3 as well.
std::vector<Event> sampleRun() {
  const Eigen::Isometry3d I = Eigen::Isometry3d::Identity();
  std::vector<Event> run;
  const auto add = [&](const std::string& channel, std::vector<std::uint8_t> data, std::int64_t utime) {
    run.push_back({channel, std::move(data), utime});
  };
  add("ODOM_MAPPED", adit::msg::encode(odometry(1000000, poseXYZYaw(0, 0, 0, 0), I)), 1000000);
  add("MAP_UPDATE", adit::msg::encode(mapUpdate(1000000, poseXYZYaw(0, 0, 0, 0), true)), 1000000);
  add("ODOM_MAPPED", adit::msg::encode(odometry(2000000, poseXYZYaw(1, 0, 0, 0), I)), 2000000);
  add("STATUS_FEATURE", adit::msg::encode(status("feature", 1700000000000000)), 2000000);
  add("POSE_GRAPH",
      adit::msg::encode(poseGraph(2000000, {{1000000, poseXYZYaw(0, 0, 0, 0)}, {2000000, poseXYZYaw(1, 0.5, 0, 0)}},
                                  2000000, 1000000)),
      2000000);
  add("MAP_UPDATE", adit::msg::encode(mapUpdate(2000000, poseXYZYaw(0, 0.25, 0, 0), false)), 2000000);
  // Published with the correction the mapper applied by then (+0.5 m in y): uncorrected (2, 0, 0).
  add("ODOM_MAPPED", adit::msg::encode(odometry(3000000, poseXYZYaw(2, 0.5, 0, 0), poseXYZYaw(0, 0.5, 0, 0))), 3000000);
  add("LOOP_CLOSURE", [] {
    adit::loop_closure_t l{};
    setHeader(l.header, 2000000);
    l.query_utime = 2000000;
    l.match_utime = 1000000;
    l.relative_orientation[0] = 1;
    return adit::msg::encode(l);
  }(), 3000000);
  // Bad input: bytes of nothing, an IMU sample on POSE_GRAPH, a pose going back in time; and an ignored channel.
  add("ODOM_MAPPED", {1, 2, 3, 4, 5, 6, 7, 8, 9}, 3000000);
  adit::imu_t imu{};
  setHeader(imu.header, 3000000);
  imu.orientation[0] = 1;
  add("POSE_GRAPH", adit::msg::encode(imu), 3000000);
  add("ODOM_MAPPED", adit::msg::encode(odometry(1500000, poseXYZYaw(9, 9, 9, 0), I)), 3000000);
  add("IMU", adit::msg::encode(imu), 3000000);
  return run;
}

TEST(RunModel, TrajectoriesLoopsMapAndStatusFromMessages) {
  RunModel model;
  RunDecoder decoder;
  for (const Event& e : sampleRun()) decoder.apply(e.channel, e.data.data(), e.data.size(), model);

  ASSERT_EQ(model.odometry.size(), 3u);  // the pose from the past is refused
  EXPECT_NEAR((model.odometry[2].pose.translation() - Eigen::Vector3d(2, 0, 0)).norm(), 0, 1e-9);
  const auto corrected = model.correctedTrajectory();
  ASSERT_EQ(corrected.size(), 3u);
  EXPECT_NEAR((corrected[0].pose.translation() - Eigen::Vector3d(0, 0, 0)).norm(), 0, 1e-9);
  EXPECT_NEAR((corrected[1].pose.translation() - Eigen::Vector3d(1, 0.5, 0)).norm(), 0, 1e-9);
  EXPECT_NEAR((corrected[2].pose.translation() - Eigen::Vector3d(2, 0.5, 0)).norm(), 0, 1e-9);
  EXPECT_NEAR(model.distance(), 2.0, 1e-9);

  ASSERT_EQ(model.loops.size(), 1u);  // POSE_GRAPH's newest loop and LOOP_CLOSURE are the same loop
  const auto segments = model.loopSegments();
  ASSERT_EQ(segments.size(), 1u);
  EXPECT_NEAR((segments[0].first - Eigen::Vector3d(1, 0.5, 0)).norm(), 0, 1e-9);
  EXPECT_NEAR((segments[0].second - Eigen::Vector3d(0, 0, 0)).norm(), 0, 1e-9);

  const auto map = model.mapPoints();  // the submap moved +0.25 m in y
  ASSERT_EQ(map.size(), 2u);
  EXPECT_NEAR((map[0] - Eigen::Vector3f(1, 0.25f, 0)).norm(), 0, 1e-6);
  EXPECT_NEAR((map[1] - Eigen::Vector3f(0, 2.25f, 0)).norm(), 0, 1e-6);
  EXPECT_EQ(model.submaps.at(0).version, 2u);

  ASSERT_EQ(model.status.count("feature"), 1u);
  EXPECT_EQ(model.status.at("feature").state, "behind");
  EXPECT_EQ(model.status.at("feature").counters.at(0).second, 3);

  EXPECT_EQ(decoder.counts().malformed, 2);
  EXPECT_EQ(decoder.counts().out_of_order, 1);
  EXPECT_EQ(decoder.counts().ignored.at("IMU"), 1);
  EXPECT_EQ(decoder.counts().used, 8);
}

// Logs recorded before odometry_t carried the accelerometer's preintegration and gravity (session 31) hold the
// older layout on ODOM_MAPPED and GROUND_TRUTH: still read, and named by `adit info`.
TEST(RunModel, OdometryOfOlderLogsIsStillRead) {
  adit::odometry_v1_t old{};
  setHeader(old.header, 5000000);
  adit::splitPose(poseXYZYaw(3, 4, 5, 0.5), old.position, old.orientation);
  adit::splitPose(Eigen::Isometry3d::Identity(), old.loop_correction_position, old.loop_correction_orientation);
  for (auto* set : {&old.corners, &old.surfaces, &old.cloud}) set->scale = 0.001f;
  const std::vector<std::uint8_t> bytes = adit::msg::encode(old);
  EXPECT_EQ(adit::msg::messageTypeName(bytes.data(), bytes.size()), "odometry_v1_t");
  RunModel model;
  RunDecoder decoder;
  decoder.apply("GROUND_TRUTH", bytes.data(), bytes.size(), model);
  decoder.apply("ODOM_MAPPED", bytes.data(), bytes.size(), model);
  EXPECT_EQ(decoder.counts().malformed, 0);
  ASSERT_EQ(model.ground_truth.size(), 1u);
  ASSERT_EQ(model.odometry.size(), 1u);
  EXPECT_NEAR((model.odometry[0].pose.translation() - Eigen::Vector3d(3, 4, 5)).norm(), 0, 1e-9);
  EXPECT_NEAR(adit::rotationAngle(model.ground_truth[0].pose), 0.5, 1e-9);
  // Bytes of neither layout are still refused.
  std::vector<std::uint8_t> garbage = bytes;
  garbage[3] ^= 0xff;
  decoder.apply("ODOM_MAPPED", garbage.data(), garbage.size(), model);
  EXPECT_EQ(decoder.counts().malformed, 1);
}

TEST(FoxgloveRun, EveryTopicOfTheRunIsWrittenToMcap) {
  std::ostringstream out;
  adit::io::McapOptions options;
  options.compression = adit::io::McapCompression::None;
  adit::io::McapWriter writer(out, options);
  adit::foxglove::McapSink sink(writer);
  adit::foxglove::FoxgloveRun exporter(sink, {});
  for (const Event& e : sampleRun()) exporter.add(e.channel, e.data.data(), e.data.size(), e.utime);
  exporter.finish();
  writer.finish();
  const auto& topics = exporter.topics();
  EXPECT_EQ(topics.at("/tf"), 3u);
  EXPECT_EQ(topics.at("/status/feature"), 1u);
  EXPECT_GE(topics.at("/loops"), 1u);
  EXPECT_GE(topics.at("/map"), 2u);  // the first submap, then at once when the loop moved it
  EXPECT_GE(topics.at("/trajectory/corrected"), 2u);
  EXPECT_EQ(exporter.decodeCounts().malformed, 2);
  EXPECT_EQ(writer.statistics().messages, [&] {
    std::uint64_t n = 0;
    for (const auto& [topic, count] : topics) n += count;
    return n;
  }());
  // The loops entity carries the corrected keyframe positions.
  const std::string file = out.str();
  EXPECT_NE(file.find(R"("points":[{"x":1,"y":0.5,"z":0},{"x":0,"y":0,"z":0}])"), std::string::npos);
}

}  // namespace

// The session sends a browser only what it lacks: a late joiner gets every submap once (flow-controlled,
// nothing dropped), then a loop's move arrives as a pose only; trajectories are appended.
#include "view/view_session.hpp"
#include "view/view_stream.hpp"
#include "ws_client.hpp"

namespace {

adit::map_update_t bigUpdate(int first_id, int count, std::int64_t utime) {
  adit::map_update_t m{};
  setHeader(m.header, utime);
  for (int id = first_id; id < first_id + count; ++id) {
    adit::map_submap_t s{};
    s.id = id;
    s.utime = utime;
    adit::splitPose(poseXYZYaw(id, 0, 0, 0), s.position, s.orientation);
    for (int i = 0; i < 5000; ++i) s.points.push_back({0.01f * static_cast<float>(i % 100), 0.02f * static_cast<float>(i / 100), 1.0f});
    s.num_points = 5000;
    m.new_submaps.push_back(s);
  }
  m.num_new = count;
  m.num_submaps = first_id + count;
  return m;
}

TEST(ViewSession, LateJoinerGetsTheMapOnceThenOnlyWhatChanged) {
  adit::view::WebServerOptions options;
  options.port = 0;
  adit::view::WebServer server(options);
  adit::view::ViewSession session(server, {});
  const auto feed = [&](const std::string& channel, const std::vector<std::uint8_t>& bytes) {
    session.apply(channel, bytes.data(), bytes.size());
  };
  feed("MAP_UPDATE", adit::msg::encode(bigUpdate(0, 80, 1000000)));  // 80 x 30 kB: more than one tick's share
  const Eigen::Isometry3d I = Eigen::Isometry3d::Identity();
  for (int i = 1; i <= 20; ++i) feed("ODOM_MAPPED", adit::msg::encode(odometry(i * 100000, poseXYZYaw(0.1 * i, 0, 0, 0), I)));

  adit::test::WsClient client(server, server.port());
  ASSERT_TRUE(client.ok());
  std::map<int, int> submap_frames, pose_frames;
  std::size_t odometry_points = 0;
  double t = 0;
  const auto run = [&](int ticks) {
    for (int k = 0; k < ticks; ++k) {
      session.tick(t += 0.05, "");
      for (const std::string& bytes : client.frames(5)) {
        adit::view::DecodedFrame f;
        ASSERT_TRUE(adit::view::decodeFrame(bytes, f));
        if (f.type == adit::view::FrameType::Submap) ++submap_frames[static_cast<int>(f.id)];
        if (f.type == adit::view::FrameType::SubmapPose) ++pose_frames[static_cast<int>(f.id)];
        if (f.type == adit::view::FrameType::Trajectory && f.kind == adit::view::TrajectoryKind::Odometry)
          odometry_points = (f.replace ? 0 : odometry_points) + f.points.size();
      }
    }
  };
  run(60);
  EXPECT_EQ(submap_frames.size(), 80u);
  for (const auto& [id, n] : submap_frames) EXPECT_EQ(n, 1) << "submap " << id;
  EXPECT_TRUE(pose_frames.empty());
  EXPECT_EQ(odometry_points, 20u);
  EXPECT_EQ(server.counters().frames_dropped, 0);

  // A loop moves submap 7; two more poses.
  feed("MAP_UPDATE", adit::msg::encode(mapUpdate(3000000, poseXYZYaw(7, 0.3, 0, 0), false)));  // moves id 0
  for (int i = 21; i <= 22; ++i) feed("ODOM_MAPPED", adit::msg::encode(odometry(i * 100000, poseXYZYaw(0.1 * i, 0, 0, 0), I)));
  const std::int64_t before = server.bytesSent(server.clients().at(0));
  run(10);
  EXPECT_EQ(pose_frames, (std::map<int, int>{{0, 1}}));
  for (const auto& [id, n] : submap_frames) EXPECT_EQ(n, 1) << "submap " << id << " resent";
  EXPECT_EQ(odometry_points, 22u);
  EXPECT_LT(server.bytesSent(server.clients().at(0)) - before, 2000);  // a pose, two positions, info: no points
}

}  // namespace

#include "foxglove/foxglove_client.hpp"

namespace adit::foxglove {
namespace {

TEST(FoxgloveClient, SubscribeAndUnsubscribeAreReadKeysInAnyOrder) {
  const ClientRequest s = parseClientRequest(
      R"({"op" : "subscribe", "subscriptions": [{"id": 1, "channelId": 3}, {"channelId":5,"id":2}, {"id": 9}]})");
  EXPECT_EQ(s.op, ClientRequest::Op::kSubscribe);
  EXPECT_EQ(s.subscribe, (std::vector<std::pair<std::uint32_t, int>>{{1, 3}, {2, 5}}));
  const ClientRequest u = parseClientRequest(R"({"op":"unsubscribe","subscriptionIds":[1, 2]})");
  EXPECT_EQ(u.op, ClientRequest::Op::kUnsubscribe);
  EXPECT_EQ(u.unsubscribe, (std::vector<std::uint32_t>{1, 2}));
  EXPECT_EQ(parseClientRequest(R"({"op":"advertise"})").op, ClientRequest::Op::kOther);
  EXPECT_EQ(parseClientRequest("save_map x").op, ClientRequest::Op::kOther);
}

// What used to stop adit view --foxglove from the LAN: a 20-digit id (std::stol threw out of the view loop)
// and a 60 kB object (std::regex recursed once per character and overflowed the stack).
TEST(FoxgloveClient, HugeNumbersAndLongObjectsAreHarmless) {
  const ClientRequest big = parseClientRequest(
      R"({"op":"subscribe","subscriptions":[{"id":99999999999999999999,"channelId":1},{"id":4294967295,"channelId":4294967295}]})");
  EXPECT_TRUE(big.subscribe.empty());
  EXPECT_EQ(parseClientRequest(R"({"op":"unsubscribe","subscriptionIds":[123456789012345678901234567890, 7]})").unsubscribe,
            std::vector<std::uint32_t>{7});
  const std::string long_object = R"({"op":"subscribe","subscriptions":[{"id":1,)" + std::string(60000, ' ') + R"("channelId":2}]})";
  EXPECT_EQ(parseClientRequest(long_object).subscribe, (std::vector<std::pair<std::uint32_t, int>>{{1, 2}}));
}

}  // namespace
}  // namespace adit::foxglove
