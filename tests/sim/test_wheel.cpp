// The simulator's wheel / track odometry (sim/wheel_model.hpp): slip within 3-8 %, noise, deterministic from
// the seed, and the other streams unchanged when it is switched on.
#include "sim/simulator.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <utility>
#include <vector>

namespace adit::sim {
namespace {

SimConfig straight(bool wheel, std::uint64_t seed = 3) {
  SimConfig c;
  c.world = "roadway-straight";
  c.duration_s = 12.0;
  c.seed = seed;
  c.wheel.enabled = wheel;
  return c;
}

TEST(WheelOdometry, SlipsThreeToEightPercentWithNoiseAndDeterministically) {
  Simulator sim(straight(true)), again(straight(true));
  SimEvent ev, ev2;
  double wheel_distance = 0.0, true_distance = 0.0;
  int readings = 0;
  std::int64_t last = -1;
  while (sim.next(ev)) {
    ASSERT_TRUE(again.next(ev2));
    ASSERT_EQ(ev.kind, ev2.kind);
    if (ev.kind != SimEvent::Kind::Wheel) continue;
    EXPECT_EQ(ev.wheel.speed, ev2.wheel.speed);  // same seed, same bits
    EXPECT_EQ(ev.wheel.yaw_rate, ev2.wheel.yaw_rate);
    if (last >= 0) {
      EXPECT_EQ(ev.wheel.utime - last, 20000);  // 50 Hz
      const double dt = 0.02;
      wheel_distance += ev.wheel.speed * dt;
      const TrajectoryState s = sim.trajectory().state(sim.secondsOf(ev.wheel.utime));
      true_distance += (s.pose.linear().transpose() * s.velocity).x() * dt;
    }
    last = ev.wheel.utime;
    ++readings;
  }
  EXPECT_EQ(readings, 601);
  ASSERT_GT(true_distance, 8.0);
  const double slip = wheel_distance / true_distance - 1.0;
  std::printf("wheel: %.2f m measured over %.2f m driven: slip %.2f %%\n", wheel_distance, true_distance, 100 * slip);
  EXPECT_GT(slip, 0.03);
  EXPECT_LT(slip, 0.08);
  // Another seed slips differently.
  Simulator other(straight(true, 4));
  double other_distance = 0.0;
  while (other.next(ev))
    if (ev.kind == SimEvent::Kind::Wheel) other_distance += ev.wheel.speed * 0.02;
  EXPECT_NE(other_distance, wheel_distance);
}

TEST(WheelOdometry, SwitchingItOnChangesNoOtherStream) {
  Simulator with(straight(true)), without(straight(false));
  SimEvent a, b;
  int sweeps = 0;
  while (without.next(b)) {
    do ASSERT_TRUE(with.next(a));
    while (a.kind == SimEvent::Kind::Wheel);
    ASSERT_EQ(a.kind, b.kind);
    if (a.kind == SimEvent::Kind::Imu) {
      EXPECT_EQ(a.imu.gyro, b.imu.gyro);
      EXPECT_EQ(a.imu.accel, b.imu.accel);
    } else if (++sweeps % 50 == 0) {
      ASSERT_EQ(a.scan.points.size(), b.scan.points.size());
      EXPECT_EQ(a.scan.points.back().p, b.scan.points.back().p);
    }
  }
}

TEST(WheelOdometry, ReferenceWorldFileListsTheDefaults) {
  const SimConfig c = simConfigFrom(adit::Config::fromYamlFile(ADIT_SOURCE_DIR "/launch/worlds/roadway-loop.yaml"));
  const WheelOdomConfig d;
  EXPECT_EQ(c.wheel.enabled, d.enabled);
  EXPECT_EQ(c.wheel.noiseless, d.noiseless);
  for (const auto& [a, b] : std::vector<std::pair<double, double>>{
           {c.wheel.rate_hz, d.rate_hz}, {c.wheel.slip_min, d.slip_min}, {c.wheel.slip_max, d.slip_max},
           {c.wheel.slip_swing, d.slip_swing}, {c.wheel.slip_period_s, d.slip_period_s},
           {c.wheel.yaw_scale_max, d.yaw_scale_max}, {c.wheel.speed_noise, d.speed_noise},
           {c.wheel.yaw_rate_noise, d.yaw_rate_noise}})
    EXPECT_DOUBLE_EQ(a, b);
}

}  // namespace
}  // namespace adit::sim
