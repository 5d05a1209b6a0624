// The pipelined bus must deliver and publish exactly what the one-threaded lockstep bus does, in the same
// order, on a topology shaped like the pipeline's: feedback inside the upstream group (ODOM_SCAN back to the
// feature stage), a message both groups take, feedback inside the downstream group (POSE_GRAPH back to the
// mapper), inputs only the downstream group takes (commands), and publications at finish.
#include "runtime/lockstep.hpp"
#include "runtime/pipelined_bus.hpp"

#include "adit/imu_t.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <stdexcept>

namespace {

using adit::runtime::Bytes;

Bytes imuBytes(std::int64_t utime, double tag = 0.0) {
  adit::imu_t m{};
  m.header.utime = utime;
  m.orientation[0] = 1.0;
  m.angular_velocity[0] = tag;
  Bytes b(static_cast<std::size_t>(m.getEncodedSize()));
  m.encode(b.data(), 0, static_cast<int>(b.size()));
  return b;
}

// Takes IMU messages on its input channels and, for each, publishes `copies` messages on each output channel
// when the input came on one of `triggers` (other inputs are only recorded); publishes once per output at finish.
class FanNode : public adit::runtime::Node {
 public:
  FanNode(std::string name, std::vector<std::string> inputs, std::vector<std::string> triggers,
          std::vector<std::string> outputs, int copies = 1)
      : Node(std::move(name)), outputs_(std::move(outputs)) {
    for (const std::string& in : inputs) {
      const bool trigger = std::find(triggers.begin(), triggers.end(), in) != triggers.end();
      subscribe<adit::imu_t>(
          "in_" + in, in,
          [this, in, trigger, copies](const adit::imu_t& m) {
            seen.push_back(in + "@" + std::to_string(m.header.utime));
            if (!trigger) return;
            for (int c = 0; c < copies; ++c) publishAll(m.header.utime + c);
          },
          adit::runtime::InputKind::Requests);
    }
    for (const std::string& out : outputs_) advertise("out_" + out, out);
  }
  std::vector<std::string> seen;

 protected:
  void onFinish() override { publishAll(999'000); }

 private:
  void publishAll(std::int64_t utime) {
    for (const std::string& out : outputs_) {
      adit::imu_t m{};
      m.header.utime = utime;
      m.orientation[0] = 1.0;
      publish("out_" + out, m);
    }
  }
  std::vector<std::string> outputs_;
};

struct Pipeline {
  FanNode feature{"feature", {"IN", "S"}, {"IN"}, {"F", "T"}, 2};
  FanNode odometry{"odometry", {"F", "IN"}, {"F"}, {"S"}, 2};
  FanNode mapper{"mapper", {"S", "T", "G", "CMD"}, {"S", "CMD"}, {"M"}};
  FanNode loop{"loop", {"M"}, {"M"}, {"G", "OUT"}, 2};
  std::vector<adit::runtime::Node*> nodes() { return {&feature, &odometry, &mapper, &loop}; }
  std::vector<std::vector<std::string>> seen() const { return {feature.seen, odometry.seen, mapper.seen, loop.seen}; }
};

// The pipeline's nodes on the bus, every publication recorded as "channel#seq@utime" into `observed`.
template <class Bus>
void connect(Bus& bus, Pipeline& p, std::vector<std::string>& observed) {
  for (auto* node : p.nodes()) bus.add(*node);
  bus.observe([&observed](const std::string& ch, const Bytes& data, std::int64_t utime) {
    adit::imu_t m;
    m.decode(data.data(), 0, static_cast<int>(data.size()));
    observed.push_back(ch + "#" + std::to_string(m.header.seq) + "@" + std::to_string(utime));
  });
}

template <class Bus>
void injectInputs(Bus& bus) {
  for (int i = 1; i <= 300; ++i) {
    bus.inject("IN", imuBytes(i * 1000), i * 1000);
    if (i % 37 == 0) bus.inject("CMD", imuBytes(i * 1000 + 1), i * 1000 + 1);
    if (i % 50 == 0) bus.inject("UNUSED", imuBytes(i * 1000 + 2), i * 1000 + 2);
  }
}

template <class Bus>
std::vector<std::string> run(Bus& bus, Pipeline& p) {
  std::vector<std::string> observed;
  connect(bus, p, observed);
  injectInputs(bus);
  bus.finish();
  return observed;
}

TEST(PipelinedBus, CutsWhereNothingFlowsBack) {
  Pipeline p;
  EXPECT_EQ(adit::runtime::pipelineSplit(p.nodes()), 2u);  // mapper's inputs come from odometry only
  EXPECT_EQ(adit::runtime::pipelineSplit({&p.mapper, &p.loop}), 0u);  // POSE_GRAPH flows back
  EXPECT_EQ(adit::runtime::pipelineSplit({&p.feature}), 0u);
  FanNode echo("echo", {"M"}, {"M"}, {"IN"});  // would feed the feature stage from downstream
  EXPECT_EQ(adit::runtime::pipelineSplit({&p.feature, &p.odometry, &p.mapper, &p.loop, &echo}), 0u);
}

TEST(PipelinedBus, SameDeliveriesAndPublicationsAsTheLockstepBus) {
  Pipeline serial_nodes, pipelined_nodes;
  adit::runtime::LockstepBus serial;
  const auto expected = run(serial, serial_nodes);
  adit::runtime::PipelinedBus pipelined;
  const auto observed = run(pipelined, pipelined_nodes);
  EXPECT_EQ(pipelined.split(), 2u);
  ASSERT_GT(expected.size(), 5000u);
  EXPECT_EQ(observed, expected);
  EXPECT_EQ(pipelined_nodes.seen(), serial_nodes.seen());
  EXPECT_EQ(pipelined_nodes.mapper.seen.back(), serial_nodes.mapper.seen.back());  // finish publications too
}

TEST(PipelinedBus, RunsOneThreadedWithoutACutOrWhenAsked) {
  for (const bool ask : {true, false}) {
    Pipeline serial_nodes, pipelined_nodes;
    FanNode echo_a("echo", {"OUT"}, {}, {}), echo_b("echo", {"OUT"}, {}, {});
    adit::runtime::LockstepBus serial;
    serial.add(echo_a);
    const auto expected = run(serial, serial_nodes);
    adit::runtime::PipelinedBus bus(ask);
    bus.add(echo_b);  // first in order: it takes the loop's output, so no cut exists
    const auto observed = run(bus, pipelined_nodes);
    EXPECT_EQ(bus.split(), 0u);
    EXPECT_EQ(observed, expected);
    EXPECT_EQ(echo_b.seen, echo_a.seen);
  }
}

TEST(PipelinedBus, DestroyedWithoutFinishItStopsAfterAPrefixOfTheOneThreadedOrder) {
  Pipeline serial_nodes, pipelined_nodes;
  adit::runtime::LockstepBus serial;
  const auto expected = run(serial, serial_nodes);
  std::vector<std::string> observed;
  {
    adit::runtime::PipelinedBus bus;
    connect(bus, pipelined_nodes, observed);
    injectInputs(bus);
  }  // the caller stopped: no finish
  ASSERT_LE(observed.size(), expected.size());
  EXPECT_TRUE(std::equal(observed.begin(), observed.end(), expected.begin()));
  const auto& mapper = pipelined_nodes.mapper.seen;
  EXPECT_TRUE(std::equal(mapper.begin(), mapper.end(), serial_nodes.mapper.seen.begin()));
}

TEST(PipelinedBus, AnObserversExceptionReachesTheCaller) {
  Pipeline p;
  adit::runtime::PipelinedBus bus;
  for (auto* node : p.nodes()) bus.add(*node);
  bus.observe([](const std::string& ch, const Bytes&, std::int64_t) {
    if (ch == "G") throw std::runtime_error("disk full");
  });
  EXPECT_THROW(
      {
        for (int i = 1; i <= 100; ++i) bus.inject("IN", imuBytes(i * 1000), i * 1000);
        bus.finish();
      },
      std::runtime_error);
}

}  // namespace
