// The node's input checks against forged or corrupt messages: oversized counts, impossible values, stamps
// in the future, clocks that restart, forged sequence numbers. Each is counted and the stream goes on.
#include "msg/convert.hpp"
#include "runtime/node.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <string>
#include <utility>

using adit::runtime::Bytes;

namespace {

class ImuNode : public adit::runtime::Node {
 public:
  ImuNode() : Node("imu-node") {
    subscribe<adit::imu_t>("imu", "IMU", [this](const adit::imu_t& m) { utimes.push_back(m.header.utime); });
  }
  std::vector<std::int64_t> utimes;
  int jumps = 0;

 protected:
  void onTimeJump(const std::string&) override { ++jumps; }
};

class NullSink : public adit::runtime::Sink {
 public:
  void publish(const std::string&, const Bytes&, std::int64_t) override {}
};

adit::imu_t imu(std::int64_t utime, std::int64_t seq = -1) {
  adit::ImuSample s;
  s.utime = utime;
  s.accel = Eigen::Vector3d(0, 0, 9.81);
  adit::imu_t m = adit::msg::toMessage(s);
  m.header.seq = seq;
  return m;
}

void send(ImuNode& node, const adit::imu_t& m) {
  NullSink sink;
  const Bytes b = adit::msg::encode(m);
  node.deliver("IMU", b.data(), b.size(), sink);
}

std::int64_t counter(const adit::runtime::Node& n, const std::string& name) {
  const auto it = n.health().counters.find(name);
  return it == n.health().counters.end() ? 0 : it->second;
}

constexpr std::int64_t kMs = 1000, kS = 1'000'000;

}  // namespace

TEST(InputChecks, OneFutureStampIsDroppedAndDoesNotBlockTheStream) {
  ImuNode node;
  for (int i = 1; i <= 5; ++i) send(node, imu(i * 5 * kMs));
  send(node, imu(1000 * kS));  // forged: far ahead
  for (int i = 6; i <= 10; ++i) send(node, imu(i * 5 * kMs));
  EXPECT_EQ(node.utimes.size(), 10u);
  EXPECT_EQ(node.utimes.back(), 50 * kMs);
  EXPECT_EQ(counter(node, "time_future"), 1);
  EXPECT_EQ(counter(node, "time_backwards"), 0);
  EXPECT_EQ(node.jumps, 0);
}

// Found by the mutation campaign: a stamp within max_future_s (2 s) but many periods ahead used to be adopted,
// and the valid messages of the next second dropped as going backwards.
TEST(InputChecks, AStampManyPeriodsAheadWithinTheFutureLimitIsHeldNotAdopted) {
  ImuNode node;
  for (int i = 1; i <= 10; ++i) send(node, imu(i * 5 * kMs));
  send(node, imu(50 * kMs + 1 * kS));  // forged: 1 s (200 periods) ahead, within max_future_s
  for (int i = 11; i <= 20; ++i) send(node, imu(i * 5 * kMs));
  EXPECT_EQ(node.utimes.size(), 20u);
  EXPECT_EQ(node.utimes.back(), 100 * kMs);
  EXPECT_EQ(counter(node, "time_future"), 1);
  EXPECT_EQ(counter(node, "time_backwards"), 0);
  EXPECT_EQ(node.jumps, 0);
}

TEST(InputChecks, AShortGapOfLostMessagesIsDelayedNotLost) {
  ImuNode node;
  for (int i = 1; i <= 10; ++i) send(node, imu(i * 5 * kMs));
  for (int i = 21; i <= 25; ++i) send(node, imu(i * 5 * kMs));  // 10 messages lost: held until confirmed
  EXPECT_EQ(node.utimes.size(), 15u);
  EXPECT_EQ(node.utimes[10], 105 * kMs);
  EXPECT_EQ(counter(node, "time_future"), 0);
}

TEST(InputChecks, ARealStallIsAcceptedAsATimeJumpOnceTheStreamContinues) {
  ImuNode node;
  for (int i = 1; i <= 5; ++i) send(node, imu(i * 5 * kMs));
  for (int i = 0; i < 5; ++i) send(node, imu(10 * kS + i * 5 * kMs));  // the sensor stalled 10 s
  EXPECT_EQ(node.utimes.size(), 10u);  // nothing lost: the held messages are delivered on confirmation
  EXPECT_EQ(node.utimes[5], 10 * kS);
  EXPECT_EQ(counter(node, "time_jump"), 1);
  EXPECT_EQ(node.jumps, 1);
  EXPECT_EQ(counter(node, "time_future"), 0);
}

TEST(InputChecks, AClockThatRestartsIsFollowedAfterConfirmation) {
  ImuNode node;
  for (int i = 1; i <= 5; ++i) send(node, imu(100 * kS + i * 5 * kMs));
  send(node, imu(50 * kS));  // one stale message: dropped
  for (int i = 6; i <= 7; ++i) send(node, imu(100 * kS + i * 5 * kMs));
  for (int i = 0; i < 10; ++i) send(node, imu(i * 5 * kMs));  // the sensor rebooted: its clock restarts at 0
  EXPECT_EQ(counter(node, "time_backwards"), 1);
  EXPECT_EQ(counter(node, "time_resync"), 1);
  EXPECT_EQ(node.utimes.size(), 17u);
  EXPECT_EQ(node.utimes.back(), 45 * kMs);
  EXPECT_EQ(node.jumps, 1);
}

TEST(InputChecks, ForgedSequenceNumbersCountAResetNotBillionsLost) {
  ImuNode node;
  send(node, imu(1 * kMs, 0));
  send(node, imu(2 * kMs, 1));
  send(node, imu(3 * kMs, 4));  // two really lost
  send(node, imu(4 * kMs, std::numeric_limits<std::int64_t>::max() / 2));  // forged
  send(node, imu(5 * kMs, 5));
  send(node, imu(6 * kMs, 6));
  EXPECT_EQ(counter(node, "lost_input"), 2);
  EXPECT_EQ(counter(node, "seq_reset"), 2);  // the forged number, and the way back from it
  EXPECT_EQ(node.utimes.size(), 6u);
}

TEST(InputChecks, ImpossibleImuValuesAreCountedAndDropped) {
  ImuNode node;
  auto m = imu(1 * kMs);
  m.angular_velocity[2] = 1e30;
  send(node, m);
  m = imu(2 * kMs);
  m.linear_acceleration[0] = std::nan("");
  send(node, m);
  m = imu(3 * kMs);
  m.has_orientation = 1;
  m.orientation[0] = 2.0;  // not a unit quaternion
  send(node, m);
  m = imu(4 * kMs);
  m.header.frame_id.assign(100000, 'x');
  send(node, m);
  send(node, imu(5 * kMs));
  EXPECT_EQ(counter(node, "invalid_range"), 1);
  EXPECT_EQ(counter(node, "invalid_nonfinite"), 1);
  EXPECT_EQ(counter(node, "invalid_quaternion"), 1);
  EXPECT_EQ(counter(node, "invalid_string"), 1);
  EXPECT_EQ(node.health().errors, 4);
  EXPECT_EQ(node.utimes, (std::vector<std::int64_t>{5 * kMs}));
}

TEST(InputChecks, OversizedCountsAreCountedSeparately) {
  ImuNode node;
  Bytes b = adit::msg::encode(imu(1 * kMs));
  // header.frame_id's length field follows the 8-byte fingerprint and two int64s.
  b[24] = 0x7f;
  NullSink sink;
  node.deliver("IMU", b.data(), b.size(), sink);
  EXPECT_EQ(counter(node, "oversized_count"), 1);
  EXPECT_EQ(node.health().errors, 1);
  EXPECT_TRUE(node.utimes.empty());
}

namespace {

// A node that keeps the stamps of what one channel delivered to its stage.
template <class Msg>
class StampRecorder : public adit::runtime::Node {
 public:
  StampRecorder(const std::string& name, std::string channel) : Node(name), channel_(std::move(channel)) {
    subscribe<Msg>("input", channel_, [this](const Msg& m) { utimes.push_back(m.header.utime); });
  }
  void send(const Msg& m) {
    NullSink sink;
    const Bytes b = adit::msg::encode(m);
    deliver(channel_, b.data(), b.size(), sink);
  }
  std::vector<std::int64_t> utimes;

 private:
  std::string channel_;
};

struct WheelNode : StampRecorder<adit::wheel_odom_t> {
  WheelNode() : StampRecorder("wheel-node", "WHEEL_ODOM") {}
};

adit::wheel_odom_t wheel(std::int64_t utime, double speed = 1.0) {
  adit::WheelOdomSample s;
  s.utime = utime;
  s.speed = speed;
  return adit::msg::toMessage(s);
}

template <class Msg>
void send(StampRecorder<Msg>& node, const Msg& m) {
  node.send(m);
}

}  // namespace

// WHEEL_ODOM goes through the same checks as every input: its wire layout (generated from wheel_odom_t.lcm),
// finite and physically possible values, time that advances.
TEST(InputChecks, BadWheelOdometryIsCountedAndDropped) {
  WheelNode node;
  send(node, wheel(20 * kMs));
  send(node, wheel(40 * kMs, std::nan("")));
  auto m = wheel(60 * kMs);
  m.yaw_rate = std::numeric_limits<double>::infinity();
  send(node, m);
  send(node, wheel(80 * kMs, 1e4));  // 10 km/s
  m = wheel(100 * kMs);
  m.speed_sigma = -0.1;
  send(node, m);
  send(node, wheel(120 * kMs));
  send(node, wheel(10 * kMs));  // time going backwards
  send(node, wheel(140 * kMs));
  const Bytes truncated = adit::msg::encode(wheel(160 * kMs));
  NullSink sink;
  node.deliver("WHEEL_ODOM", truncated.data(), truncated.size() - 4, sink);
  EXPECT_EQ(counter(node, "invalid_nonfinite"), 2);
  EXPECT_EQ(counter(node, "invalid_range"), 2);
  EXPECT_EQ(counter(node, "time_backwards"), 1);
  EXPECT_EQ(counter(node, "oversized_count"), 1);  // truncated: its last field needs more bytes than are left
  EXPECT_EQ(node.utimes, (std::vector<std::int64_t>{20 * kMs, 120 * kMs, 140 * kMs}));
}

TEST(Messages, WheelOdometryRoundTrip) {
  adit::WheelOdomSample in{123, 1.25, -0.3, 0.02, 0.01};
  const adit::wheel_odom_t m = adit::msg::toMessage(in);
  adit::wheel_odom_t back;
  const Bytes b = adit::msg::encode(m);
  ASSERT_EQ(back.decode(b.data(), 0, static_cast<int>(b.size())), static_cast<int>(b.size()));
  const adit::WheelOdomSample out = adit::msg::fromMessage(back);
  EXPECT_EQ(out.utime, 123);
  EXPECT_EQ(out.speed, 1.25);
  EXPECT_EQ(out.yaw_rate, -0.3);
  EXPECT_EQ(out.speed_sigma, 0.02);
  EXPECT_EQ(out.yaw_rate_sigma, 0.01);
  EXPECT_EQ(back.header.frame_id, "base");
}

// Found by the sanitized suite (UBSan, signed overflow): the time checks subtracted and added corrupt stamps
// as int64. A stamp of INT64_MIN held as off-stream, then a forged one far ahead: their difference overflowed.
TEST(InputChecks, ExtremeStampsNeverOverflowTheTimeChecks) {
  ImuNode node;
  for (int i = 1; i <= 5; ++i) send(node, imu(i * 5 * kMs));
  send(node, imu(std::numeric_limits<std::int64_t>::min()));
  send(node, imu(1000 * kS));
  for (int i = 6; i <= 10; ++i) send(node, imu(i * 5 * kMs));
  EXPECT_EQ(node.utimes.size(), 10u);
  EXPECT_EQ(node.utimes.back(), 50 * kMs);
  EXPECT_EQ(node.jumps, 0);

  // A clock that restarts just below INT64_MAX is followed once confirmed, and its steps continue the stream
  // (the future limit added to the newest stamp used to wrap negative and turn every step away).
  const std::int64_t top = std::numeric_limits<std::int64_t>::max() - kS;
  for (int i = 0; i < 20; ++i) send(node, imu(top + i * 5 * kMs));
  EXPECT_EQ(node.utimes.back(), top + 19 * 5 * kMs);
  EXPECT_GE(node.utimes.size(), 10u + 15u);
}

namespace {

struct OdometryNode : StampRecorder<adit::odometry_t> {
  OdometryNode() : StampRecorder("odometry-node", "ODOM_SCAN") {}
};

adit::odometry_t odometry(std::int64_t utime) {
  adit::PoseEstimate p;
  p.utime = utime;
  p.specific_force = {utime - 100 * kMs, Eigen::Vector3d(0.1, 0, 0.98), Eigen::Vector3d(0.005, 0, 0.05)};
  p.gravity = Eigen::Vector3d(0, 0, -9.81);
  return adit::msg::toMessage(p, nullptr);
}

}  // namespace

// The accelerometer's preintegration and gravity on ODOM_SCAN / ODOM_MAPPED are optional ("none": a start of
// -1, a zero gravity), but a NaN there, an impossible gravity or a start after the sweep is a broken producer:
// counted and dropped like any other bad field, never read as "none" in silence.
TEST(InputChecks, BrokenImuFieldsOfOdometryAreCountedAndDropped) {
  OdometryNode node;
  send(node, odometry(100 * kMs));
  auto m = odometry(200 * kMs);
  m.imu_velocity_change[1] = std::nan("");
  send(node, m);
  m = odometry(300 * kMs);
  m.gravity[2] = -std::numeric_limits<double>::infinity();
  send(node, m);
  m = odometry(400 * kMs);
  m.gravity[0] = 1e4;
  send(node, m);
  m = odometry(500 * kMs);
  m.imu_since_utime = 600 * kMs;  // after the sweep it ends at
  send(node, m);
  m = odometry(600 * kMs);
  m.imu_since_utime = -1;  // none: a message without an IMU part is fine
  m.gravity[0] = m.gravity[1] = m.gravity[2] = 0.0;
  send(node, m);
  EXPECT_EQ(counter(node, "invalid_nonfinite"), 2);
  EXPECT_EQ(counter(node, "invalid_range"), 2);
  EXPECT_EQ(node.utimes, (std::vector<std::int64_t>{100 * kMs, 600 * kMs}));
}
