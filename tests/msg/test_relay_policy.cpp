// What crosses to the LAN (adit-lan-relay): only channels in scope, decimated where asked, odometry as the pose.
#include "msg/convert.hpp"
#include "msg/encode.hpp"
#include "runtime/status.hpp"
#include "sources/relay_policy.hpp"

#include <gtest/gtest.h>

namespace adit {
namespace {

runtime::Bytes odometryWithPoints() {
  FeatureSet f;
  for (int i = 0; i < 500; ++i) f.cloud.points.push_back({Eigen::Vector3f(0.1f * i, 1.0f, 2.0f), 0.0f, 0, 0.0f});
  PoseEstimate p;
  p.utime = 42;
  return msg::encode(msg::toMessage(p, &f));
}

sources::RelayPolicyConfig scope() {
  sources::RelayPolicyConfig c;
  c.channels = "^(ODOM_MAPPED|POSE_GRAPH|STATUS_.*|LIDAR_POINTS)$";
  c.poses_only = "^(ODOM_MAPPED)$";
  c.every["LIDAR_POINTS"] = 10;
  return c;
}

TEST(RelayPolicy, OnlyChannelsInScopeCross) {
  sources::RelayPolicy policy(scope());
  const runtime::Bytes some{1, 2, 3};
  EXPECT_TRUE(policy.forward("STATUS_FEATURE", some).has_value());
  EXPECT_TRUE(policy.forward("POSE_GRAPH", some).has_value());
  for (const char* heavy : {"FEATURES", "ODOM_SCAN", "IMU", "STATUS"})
    EXPECT_FALSE(policy.forward(heavy, some).has_value()) << heavy;
}

TEST(RelayPolicy, DecimatedChannelsForwardOneInN) {
  sources::RelayPolicy policy(scope());
  int forwarded = 0;
  for (int i = 0; i < 100; ++i) forwarded += policy.forward("LIDAR_POINTS", {9}).has_value() ? 1 : 0;
  EXPECT_EQ(forwarded, 10);
}

TEST(RelayPolicy, OdometryCrossesAsThePoseAlone) {
  sources::RelayPolicy policy(scope());
  const runtime::Bytes full = odometryWithPoints();
  const auto out = policy.forward("ODOM_MAPPED", full);
  ASSERT_TRUE(out.has_value());
  EXPECT_LT(out->size() * 4, full.size());
  adit::odometry_t m;
  ASSERT_GT(m.decode(out->data(), 0, static_cast<int>(out->size())), 0);
  EXPECT_EQ(m.header.utime, 42);
  EXPECT_EQ(m.cloud.num_points, 0);
  // Not an odometry_t on a pose-only channel: nothing crosses.
  EXPECT_FALSE(policy.forward("ODOM_MAPPED", {1, 2, 3}).has_value());
}

TEST(RelayPolicy, BadSettingsAreRefused) {
  sources::RelayPolicyConfig bad = scope();
  bad.channels = "(";
  EXPECT_THROW(sources::RelayPolicy{bad}, std::runtime_error);
  bad = scope();
  bad.every["LIDAR_POINTS"] = 0;
  EXPECT_THROW(sources::RelayPolicy{bad}, std::runtime_error);
  EXPECT_EQ(sources::parseEvery("LIDAR_POINTS=10"), std::make_pair(std::string("LIDAR_POINTS"), 10));
  EXPECT_THROW(sources::parseEvery("LIDAR_POINTS"), std::runtime_error);
  EXPECT_THROW(sources::parseEvery("LIDAR_POINTS=x"), std::runtime_error);
}

TEST(PublishedTraffic, StatusCarriesBytesAndMessagesPerSecondPerChannel) {
  runtime::PublishedTraffic traffic;
  for (int i = 0; i < 10; ++i) traffic.add("FEATURES", 90'000);
  traffic.add("STATUS_FEATURE", 500);
  adit::status_t s = runtime::makeStatus("feature", runtime::Health{}, runtime::TimingWindow{}, 0, 0, 1.0, 0, 0, "running");
  traffic.report(s, 2.0);
  ASSERT_EQ(s.num_channels, 2);
  EXPECT_EQ(s.channel_names[0], "FEATURES");
  EXPECT_FLOAT_EQ(s.channel_bytes_per_s[0], 450'000.0f);
  EXPECT_FLOAT_EQ(s.channel_messages_per_s[0], 5.0f);
  EXPECT_FLOAT_EQ(s.channel_bytes_per_s[1], 250.0f);
  // The next window starts empty; a silent channel stays listed at 0.
  traffic.add("STATUS_FEATURE", 500);
  traffic.report(s, 1.0);
  ASSERT_EQ(s.num_channels, 2);
  EXPECT_EQ(s.channel_bytes_per_s[0], 0.0f);
  EXPECT_FLOAT_EQ(s.channel_bytes_per_s[1], 500.0f);
  const runtime::Bytes bytes = msg::encode(s);  // and it encodes
  adit::status_t back;
  EXPECT_EQ(back.decode(bytes.data(), 0, static_cast<int>(bytes.size())), static_cast<int>(bytes.size()));
}

}  // namespace
}  // namespace adit
