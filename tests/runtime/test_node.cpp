// Node input checks and the lockstep bus: bad input is counted and skipped, never thrown; delivery is FIFO
// and deterministic.
#include "msg/convert.hpp"
#include "runtime/lockstep.hpp"
#include "runtime/node.hpp"

#include <gtest/gtest.h>

using adit::runtime::Bytes;

namespace {

// Copies IMU samples to IMU_COPY; throws on a sample whose gyro x is 6.5 rad/s (a stage failure).
class CopyNode : public adit::runtime::Node {
 public:
  explicit CopyNode(std::string name = "copy", std::string in = "IMU", std::string out = "IMU_COPY")
      : Node(std::move(name)) {
    subscribe<adit::imu_t>("imu", in, [this](const adit::imu_t& m) {
      if (m.angular_velocity[0] == 6.5) throw std::runtime_error("bad sample");
      adit::imu_t copy = m;
      publish("out", copy);
    });
    advertise("out", out);
  }
  int jumps = 0;

 protected:
  void onTimeJump(const std::string&) override { ++jumps; }
};

class Collector : public adit::runtime::Sink {
 public:
  void publish(const std::string& channel, const Bytes& data, std::int64_t utime) override {
    channels.push_back(channel);
    adit::imu_t m;
    if (m.decode(data.data(), 0, static_cast<int>(data.size())) > 0) seqs.push_back(m.header.seq);
    utimes.push_back(utime);
  }
  std::vector<std::string> channels;
  std::vector<std::int64_t> seqs, utimes;
};

Bytes imuBytes(std::int64_t utime, double gx = 0.0) {
  adit::ImuSample s;
  s.utime = utime;
  s.gyro.x() = gx;
  adit::imu_t m = adit::msg::toMessage(s);
  Bytes b(static_cast<std::size_t>(m.getEncodedSize()));
  m.encode(b.data(), 0, static_cast<int>(b.size()));
  return b;
}

void deliver(adit::runtime::Node& n, const Bytes& b, adit::runtime::Sink& sink, const std::string& ch = "IMU") {
  n.deliver(ch, b.data(), b.size(), sink);
}

}  // namespace

TEST(Node, PublishesWithSequenceNumbersInOrder) {
  CopyNode node;
  Collector sink;
  for (int i = 1; i <= 3; ++i) deliver(node, imuBytes(i * 5000), sink);
  EXPECT_EQ(sink.seqs, (std::vector<std::int64_t>{0, 1, 2}));
  EXPECT_EQ(sink.utimes, (std::vector<std::int64_t>{5000, 10000, 15000}));
  EXPECT_EQ(node.health().inputs, 3);
  EXPECT_EQ(node.health().outputs, 3);
}

// A stage with threads beside its own says what they cost on STATUS (helper_cpu_ms) after every input and at
// the end; one without says nothing.
TEST(Node, CountsItsHelperThreadsCpuWhereItHasAny) {
  class Helped : public CopyNode {
   public:
    double helperCpuMs() const override { return helper_ms; }
    double helper_ms = 12.7;
  };
  Helped helped;
  CopyNode alone;
  Collector sink;
  deliver(helped, imuBytes(5000), sink);
  deliver(alone, imuBytes(5000), sink);
  EXPECT_EQ(helped.health().counters.at("helper_cpu_ms"), 12);
  EXPECT_EQ(alone.health().counters.count("helper_cpu_ms"), 0u);
  helped.helper_ms = 30.2;
  helped.finish(sink);
  EXPECT_EQ(helped.health().counters.at("helper_cpu_ms"), 30);
}

TEST(Node, UndecodableAndWrongTypeMessagesAreCountedErrors) {
  CopyNode node;
  Collector sink;
  const Bytes garbage{1, 2, 3, 4, 5, 6, 7, 8, 9};
  deliver(node, garbage, sink);
  adit::point_cloud_t other;  // a valid message of another type on the IMU channel
  other.num_points = 0;
  other.header.utime = 1;
  Bytes b(static_cast<std::size_t>(other.getEncodedSize()));
  other.encode(b.data(), 0, static_cast<int>(b.size()));
  deliver(node, b, sink);
  EXPECT_EQ(node.health().errors, 2);
  EXPECT_EQ(node.health().counters.at("decode_error"), 2);
  EXPECT_TRUE(sink.channels.empty());
  deliver(node, imuBytes(10), sink);  // and the run goes on
  EXPECT_EQ(sink.channels.size(), 1u);
}

TEST(Node, TimeGoingBackwardsOrRepeatingIsDropped) {
  CopyNode node;
  Collector sink;
  deliver(node, imuBytes(20000), sink);
  deliver(node, imuBytes(10000), sink);  // backwards
  deliver(node, imuBytes(20000), sink);  // duplicate
  deliver(node, imuBytes(25000), sink);
  EXPECT_EQ(sink.utimes, (std::vector<std::int64_t>{20000, 25000}));
  EXPECT_EQ(node.health().drops, 2);
  EXPECT_EQ(node.health().counters.at("time_backwards"), 1);
  EXPECT_EQ(node.health().counters.at("duplicate_time"), 1);
}

TEST(Node, ForwardTimeJumpIsCountedAndResetsState) {
  CopyNode node;
  node.setMaxTimeGap(1.0);
  Collector sink;
  deliver(node, imuBytes(1'000'000), sink);
  deliver(node, imuBytes(1'500'000), sink);
  deliver(node, imuBytes(2'600'000), sink);  // 1.1 s gap, within the future tolerance: adopted at once
  EXPECT_EQ(node.jumps, 1);
  EXPECT_EQ(node.health().counters.at("time_jump"), 1);
  EXPECT_EQ(sink.utimes.size(), 3u);  // the message after the gap is still processed
}

// Sparse results (loop closures, graphs) have long gaps by nature: not time jumps, but still ordered.
class EventNode : public adit::runtime::Node {
 public:
  EventNode() : Node("events") {
    subscribe<adit::imu_t>("in", "EVENTS", [this](const adit::imu_t&) { ++handled; }, adit::runtime::InputKind::Events);
  }
  int handled = 0;
};

TEST(Node, EventInputsHaveNoTimeJumpsButStayOrdered) {
  EventNode node;
  Collector sink;
  deliver(node, imuBytes(1'000'000), sink, "EVENTS");
  deliver(node, imuBytes(60'000'000), sink, "EVENTS");  // a minute later: normal for loop closures
  deliver(node, imuBytes(30'000'000), sink, "EVENTS");  // backwards: still dropped
  node.finish(sink);  // (held until the end in case the stream really went back: counted then)
  EXPECT_EQ(node.handled, 2);
  EXPECT_EQ(node.health().counters.count("time_jump"), 0u);
  EXPECT_EQ(node.health().counters.at("time_backwards"), 1);
}

TEST(Node, SequenceGapsAreCountedAsLostInput) {
  CopyNode node;
  Collector sink;
  for (std::int64_t seq : {0, 1, 4, 5}) {
    adit::ImuSample s;
    s.utime = 1000 * (seq + 1);
    adit::imu_t m = adit::msg::toMessage(s);
    m.header.seq = seq;
    Bytes b(static_cast<std::size_t>(m.getEncodedSize()));
    m.encode(b.data(), 0, static_cast<int>(b.size()));
    deliver(node, b, sink);
  }
  EXPECT_EQ(node.health().counters.at("lost_input"), 2);
  EXPECT_EQ(sink.utimes.size(), 4u);  // a loss upstream does not stop the stage
}

TEST(Node, StageExceptionIsCountedNotPropagated) {
  CopyNode node;
  Collector sink;
  EXPECT_NO_THROW(deliver(node, imuBytes(1000, 6.5), sink));
  EXPECT_EQ(node.health().counters.at("stage_exception"), 1);
  deliver(node, imuBytes(2000), sink);
  EXPECT_EQ(sink.utimes.size(), 1u);
}

TEST(Node, RemapChangesChannelsAndRejectsUnknownPorts) {
  CopyNode node;
  node.remap("imu", "IMU_RAW");
  Collector sink;
  deliver(node, imuBytes(1000), sink, "IMU");
  EXPECT_TRUE(sink.channels.empty());
  deliver(node, imuBytes(2000), sink, "IMU_RAW");
  EXPECT_EQ(sink.channels.size(), 1u);
  EXPECT_THROW(node.remap("nope", "X"), std::runtime_error);
}

TEST(LockstepBus, DeliversDownstreamInFifoOrderAndLogsOutputs) {
  CopyNode first("first", "IMU", "A");
  CopyNode second("second", "A", "B");
  adit::runtime::LockstepBus bus;
  std::vector<std::string> seen;
  bus.observe([&](const std::string& ch, const Bytes&, std::int64_t utime) { seen.push_back(ch + "@" + std::to_string(utime)); });
  bus.add(second);  // order of adding does not change causality, only visiting order per message
  bus.add(first);
  for (int i = 1; i <= 2; ++i) {
    const Bytes b = imuBytes(i * 100);
    bus.inject("IMU", b, i * 100);
  }
  bus.finish();
  EXPECT_EQ(seen, (std::vector<std::string>{"A@100", "B@100", "A@200", "B@200"}));
}
