// Packets -> sweeps through LidarPacketStream (decoder + packet clock + sweep assembler), against the
// synthetic lidar's ground truth: every point of every complete revolution, with its time, exactly once.
#include "drivers/lidar_stream.hpp"
#include "synthetic_lidar.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <iostream>
#include <functional>
#include <random>

namespace adit::drivers {
namespace {

using testing::Model;
using testing::SyntheticLidar;
using testing::TruthFiring;

constexpr std::int64_t kHost0Ns = 1700000000LL * 1000000000;  // host clock at packet 0's first firing
constexpr std::int64_t kLatencyNs = 100000;                    // last firing -> kernel receive

struct StreamRun {
  std::vector<LidarScan> sweeps;
  runtime::Health health;
};

LidarStreamConfig streamConfig(const SyntheticLidar& lidar) {
  LidarStreamConfig c;
  c.model = lidar.model == Model::kVlp16 ? LidarModel::kVlp16 : LidarModel::kRs16;
  c.sweep.sensor = lidar.model == Model::kVlp16 ? "vlp16" : "rs16";
  return c;
}

// Host receive time of packet k (ns): its last firing plus a fixed latency.
std::int64_t receiveNs(const SyntheticLidar& lidar, int k) {
  return kHost0Ns + k * lidar.packetNs() + lidar.lastFiringNs() + kLatencyNs;
}

// Feeds the packet sequence `order` (indices into the lidar's stream); `mutate` may rewrite bytes/time.
StreamRun feed(const SyntheticLidar& lidar, const std::vector<int>& order, LidarStreamConfig config,
         const std::function<void(int, std::vector<std::uint8_t>&, std::int64_t&)>& mutate = {}) {
  LidarPacketStream stream(config);
  StreamRun run;
  for (int k : order) {
    std::vector<std::uint8_t> bytes = lidar.packet(k);
    std::int64_t t = receiveNs(lidar, k);
    if (mutate) mutate(k, bytes, t);
    stream.push(bytes.data(), bytes.size(), t, run.sweeps);
  }
  run.health = stream.health();
  return run;
}

std::vector<int> range(int n) {
  std::vector<int> v(static_cast<std::size_t>(n));
  for (int i = 0; i < n; ++i) v[static_cast<std::size_t>(i)] = i;
  return v;
}

// Truth firings of packets 0..n-1, grouped by revolution: window 0 holds the firings before the first pass
// of the cut angle, window w those between the w-th and (w+1)-th pass (continuous azimuth, unwrapped).
std::size_t returnsIn(const std::vector<TruthFiring>& window) {
  return static_cast<std::size_t>(
      std::count_if(window.begin(), window.end(), [](const TruthFiring& f) { return f.has_return; }));
}

std::vector<std::vector<TruthFiring>> truthWindows(const SyntheticLidar& lidar, int n, double cut_deg = 180.0) {
  std::vector<std::vector<TruthFiring>> windows;
  for (int k = 0; k < n; ++k) {
    std::vector<TruthFiring> truth;
    lidar.packet(k, &truth);
    for (const TruthFiring& f : truth) {
      const double unwrapped = (lidar.az0_centideg + lidar.gap_centideg * static_cast<double>(f.t_ns) /
                                                         static_cast<double>(lidar.blockNs())) / 100.0;
      const double start = lidar.az0_centideg / 100.0;
      const auto w = static_cast<std::size_t>(std::floor((unwrapped - cut_deg) / 360.0) -
                                              std::floor((start - cut_deg) / 360.0));
      if (windows.size() <= w) windows.resize(w + 1);
      windows[w].push_back(f);
    }
  }
  return windows;
}

// Sweeps j = windows j+1 (window 0 began mid-revolution; the last one is still open).
// time_tol_ns: stamps are whole microseconds, so firing times are off by < 1 us (< 2 us across a re-anchor).
void expectSweepsMatchTruth(const SyntheticLidar& lidar, const StreamRun& run, int packets,
                            double time_tol_ns = 1000.0) {
  const auto windows = truthWindows(lidar, packets);
  ASSERT_GE(windows.size(), 3u);
  ASSERT_EQ(run.sweeps.size(), windows.size() - 2);
  const std::int64_t anchor = kHost0Ns + kLatencyNs;  // output time of truth t = 0 (to < 1 us)
  std::size_t points = 0, expected_points = 0;
  for (std::size_t j = 0; j < run.sweeps.size(); ++j) {
    const LidarScan& s = run.sweeps[j];
    const std::vector<TruthFiring>& w = windows[j + 1];
    std::vector<const TruthFiring*> returns;
    for (const TruthFiring& f : w)
      if (f.has_return) returns.push_back(&f);
    expected_points += returns.size();
    points += s.points.size();
    EXPECT_EQ(s.seq, static_cast<std::int64_t>(j));
    EXPECT_EQ(s.sensor, lidar.model == Model::kVlp16 ? "vlp16" : "rs16");
    EXPECT_EQ(s.num_beams, 16);
    EXPECT_TRUE(s.has_ring);
    EXPECT_TRUE(s.has_time);
    EXPECT_FALSE(s.deskewed);
    // utime = last firing of the window (returns or not); duration = last - first firing.
    EXPECT_NEAR(static_cast<double>(s.utime * 1000 - (anchor + w.back().t_ns)), 0.0, time_tol_ns + 1000.0) << "sweep " << j;
    EXPECT_NEAR(s.sweep_duration, (w.back().t_ns - w.front().t_ns) * 1e-9, 2 * time_tol_ns * 1e-9);
    ASSERT_EQ(s.points.size(), returns.size()) << "sweep " << j;
    for (std::size_t i = 0; i < returns.size(); ++i) {
      const LidarPoint& p = s.points[i];
      const TruthFiring& t = *returns[i];
      EXPECT_LT((p.p.cast<double>() - t.p).norm(), 1e-3) << "sweep " << j << " point " << i;
      EXPECT_EQ(p.ring, t.ring);
      EXPECT_EQ(p.intensity, t.intensity);
      EXPECT_NEAR(p.dt, (t.t_ns - w.back().t_ns) * 1e-9, time_tol_ns * 1e-9 + 2e-8) << "sweep " << j << " point " << i;
      EXPECT_LE(p.dt, 0.0f);
      EXPECT_GE(p.dt, -s.sweep_duration - 1e-6f);
    }
    if (j > 0) {
      EXPECT_NEAR((s.utime - run.sweeps[j - 1].utime) * 1e3, lidar.rotationNs(), 2 * time_tol_ns + 1000.0);
    }
  }
  EXPECT_EQ(points, expected_points);
  EXPECT_EQ(run.health.outputs, static_cast<std::int64_t>(run.sweeps.size()));
  EXPECT_EQ(run.health.counters.at("partial_sweep"), 1);  // window 0
  EXPECT_EQ(run.health.errors, 0);
}

struct Case {
  const char* name;
  Model model;
  bool dual;
};

class SweepsOverThreeRevolutions : public ::testing::TestWithParam<Case> {};

TEST_P(SweepsOverThreeRevolutions, EveryFiringOnceWithItsTime) {
  SyntheticLidar lidar;
  lidar.model = GetParam().model;
  lidar.dual = GetParam().dual;
  lidar.stamp0_us = lidar.model == Model::kVlp16 ? 777777 : testing::kRs16TestEpochUs + 5;
  // Enough packets for 3 complete revolutions after the partial first one (10 Hz, 0.4 deg per block).
  const int packets = static_cast<int>(3.6 * lidar.rotationNs() / static_cast<double>(lidar.packetNs()));
  const StreamRun run = feed(lidar, range(packets), streamConfig(lidar));
  EXPECT_EQ(run.sweeps.size(), 3u);
  expectSweepsMatchTruth(lidar, run, packets);
  std::cout << GetParam().name << ": " << packets << " packets -> " << run.sweeps.size() << " sweeps of "
            << run.sweeps[0].points.size() << " points, period " << (run.sweeps[1].utime - run.sweeps[0].utime)
            << " us, duration " << run.sweeps[0].sweep_duration << " s\n";
}

INSTANTIATE_TEST_SUITE_P(Models, SweepsOverThreeRevolutions,
                         ::testing::Values(Case{"vlp16", Model::kVlp16, false}, Case{"vlp16_dual", Model::kVlp16, true},
                                           Case{"rs16", Model::kRs16, false}),
                         [](const auto& info) { return std::string(info.param.name); });

const int kPackets = 270;  // VLP-16: 3.6 revolutions

TEST(PacketClock, VelodyneHourWrapIsInvisible) {
  SyntheticLidar plain;
  plain.stamp0_us = 1000000;
  SyntheticLidar wrapping = plain;
  wrapping.stamp0_us = 3600000000LL - 150000;  // wraps 0.15 s in
  ASSERT_LT(wrapping.stampUs(kPackets - 1), wrapping.stampUs(0));
  const StreamRun a = feed(plain, range(kPackets), streamConfig(plain));
  const StreamRun b = feed(wrapping, range(kPackets), streamConfig(wrapping));
  ASSERT_EQ(a.sweeps.size(), 3u);
  ASSERT_EQ(b.sweeps.size(), a.sweeps.size());
  for (std::size_t j = 0; j < a.sweeps.size(); ++j) {
    EXPECT_EQ(b.sweeps[j].utime, a.sweeps[j].utime);
    ASSERT_EQ(b.sweeps[j].points.size(), a.sweeps[j].points.size());
    for (std::size_t i = 0; i < a.sweeps[j].points.size(); ++i) EXPECT_EQ(b.sweeps[j].points[i].dt, a.sweeps[j].points[i].dt);
  }
  EXPECT_EQ(b.health.counters.count("time_reanchor"), 0u);
}

TEST(PacketClock, RepeatedOrLatePacketIsSkippedAndCounted) {
  SyntheticLidar lidar;
  std::vector<int> order = range(kPackets);
  order.insert(order.begin() + 61, 50);   // a repeat of packet 50 after packet 60
  order.insert(order.begin() + 150, 148); // packet 148 again right after itself
  const StreamRun run = feed(lidar, order, streamConfig(lidar));
  EXPECT_EQ(run.health.counters.at("time_backwards"), 2);
  EXPECT_EQ(run.health.drops, 2 + 1);  // two packets + the partial first sweep
  expectSweepsMatchTruth(lidar, run, kPackets);
}

TEST(PacketClock, SensorClockJumpReanchorsWithoutLosingSweeps) {
  SyntheticLidar lidar;
  lidar.stamp0_us = 5000000;
  // From packet 120 on, the sensor clock reads 40 s later (a GPS fix); the host clock runs on.
  const StreamRun run = feed(lidar, range(kPackets), streamConfig(lidar),
                       [&](int k, std::vector<std::uint8_t>& bytes, std::int64_t&) {
                         if (k < 120) return;
                         const std::uint32_t stamp = static_cast<std::uint32_t>(lidar.stampUs(k) + 40000000);
                         for (int i = 0; i < 4; ++i) bytes[1200 + i] = static_cast<std::uint8_t>(stamp >> (8 * i));
                       });
  EXPECT_EQ(run.health.counters.at("time_reanchor"), 1);
  // The re-anchored packet starts at its host receive time: the time line stays continuous.
  expectSweepsMatchTruth(lidar, run, kPackets, 2000.0);
}

TEST(PacketClock, HostTimeWithJitterStaysMonotonic) {
  SyntheticLidar lidar;
  LidarStreamConfig config = streamConfig(lidar);
  config.clock.source = TimeSource::kHost;
  std::mt19937 rng(3);
  std::uniform_int_distribution<std::int64_t> jitter(0, 400000);  // 0..0.4 ms of extra network/scheduling delay
  const StreamRun run = feed(lidar, range(kPackets), config,
                       [&](int, std::vector<std::uint8_t>&, std::int64_t& t) { t += jitter(rng); });
  ASSERT_EQ(run.sweeps.size(), 3u);
  EXPECT_GT(run.health.counters.at("time_shifted"), 0);
  EXPECT_EQ(run.health.counters.count("time_backwards"), 0u);
  const auto windows = truthWindows(lidar, kPackets);
  for (std::size_t j = 0; j < run.sweeps.size(); ++j) {
    const LidarScan& s = run.sweeps[j];
    // Host stamps are late by the latency plus at most the jitter.
    const double late_ns = static_cast<double>(s.utime * 1000 - (kHost0Ns + windows[j + 1].back().t_ns));
    EXPECT_GT(late_ns, kLatencyNs - 1000.0);
    EXPECT_LT(late_ns, kLatencyNs + 400000 + 1000.0);
    EXPECT_EQ(s.points.size(), returnsIn(windows[j + 1]));
    for (const LidarPoint& p : s.points) EXPECT_TRUE(p.dt <= 0.0f && p.dt >= -s.sweep_duration);
  }
}

TEST(PacketClock, HostClockStepBackSkipsPacketsUntilTimeCatchesUp) {
  SyntheticLidar lidar;
  LidarStreamConfig config = streamConfig(lidar);
  config.clock.source = TimeSource::kHost;
  // At packet 100 the host clock steps back 5 ms (NTP): ~3 packets fall behind the published time line.
  const StreamRun run = feed(lidar, range(kPackets), config,
                       [&](int k, std::vector<std::uint8_t>&, std::int64_t& t) { if (k >= 100) t -= 5000000; });
  EXPECT_GE(run.health.counters.at("time_backwards"), 2);
  EXPECT_LE(run.health.counters.at("time_backwards"), 4);
  ASSERT_EQ(run.sweeps.size(), 3u);  // a 5 ms hole is below max_firing_gap_s: no sweep lost
  for (std::size_t j = 1; j < run.sweeps.size(); ++j) EXPECT_GT(run.sweeps[j].utime, run.sweeps[j - 1].utime);
}

TEST(SweepAssembler, MalformedPacketsInTheStreamChangeNothing) {
  SyntheticLidar lidar;
  const StreamRun clean = feed(lidar, range(kPackets), streamConfig(lidar));
  LidarPacketStream stream(streamConfig(lidar));
  std::vector<LidarScan> sweeps;
  std::mt19937 rng(11);
  int junk = 0;
  for (int k = 0; k < kPackets; ++k) {
    if (k % 7 == 3) {  // garbage, a truncated copy and a corrupted copy between good packets
      std::vector<std::uint8_t> bad = lidar.packet(k);
      if (k % 3 == 0) bad.resize(rng() % 1206);
      else if (k % 3 == 1) bad[100 * (rng() % 12)] = 0x00;
      else for (auto& b : bad) b = static_cast<std::uint8_t>(rng());
      stream.push(bad.data(), bad.size(), receiveNs(lidar, k) - 1000, sweeps);
      ++junk;
    }
    const std::vector<std::uint8_t> good = lidar.packet(k);
    stream.push(good.data(), good.size(), receiveNs(lidar, k), sweeps);
  }
  EXPECT_EQ(stream.health().errors, junk);
  EXPECT_EQ(stream.health().inputs, kPackets + junk);
  ASSERT_EQ(sweeps.size(), clean.sweeps.size());
  for (std::size_t j = 0; j < sweeps.size(); ++j) {
    EXPECT_EQ(sweeps[j].utime, clean.sweeps[j].utime);
    EXPECT_EQ(sweeps[j].points.size(), clean.sweeps[j].points.size());
  }
}

TEST(PacketClock, Rs16WithoutAClockWorksOnHostTimeOnly) {
  SyntheticLidar lidar;
  lidar.model = Model::kRs16;
  lidar.stamp0_us = testing::kRs16TestEpochUs;
  const auto zeroDate = [](int, std::vector<std::uint8_t>& bytes, std::int64_t&) {
    std::fill(bytes.begin() + 20, bytes.begin() + 30, 0);  // month 0, day 0: a clock never set
  };
  LidarStreamConfig config = streamConfig(lidar);
  const StreamRun sensor = feed(lidar, range(kPackets), config, zeroDate);
  EXPECT_TRUE(sensor.sweeps.empty());
  EXPECT_EQ(sensor.health.counters.at("bad_timestamp"), kPackets);
  EXPECT_EQ(sensor.health.errors, kPackets);
  config.clock.source = TimeSource::kHost;
  const StreamRun host = feed(lidar, range(kPackets), config, zeroDate);
  EXPECT_EQ(host.sweeps.size(), 3u);
  EXPECT_EQ(host.health.errors, 0);
}

TEST(SweepAssembler, LostPacketsDropTheSweepTheyHit) {
  SyntheticLidar lidar;
  std::vector<int> order;
  for (int k = 0; k < kPackets; ++k)
    if (k < 130 || k >= 140) order.push_back(k);  // 10 packets (13 ms) lost in the 2nd full revolution
  const StreamRun run = feed(lidar, order, streamConfig(lidar));
  EXPECT_EQ(run.health.counters.at("packet_gap"), 1);
  EXPECT_EQ(run.health.counters.count("lost_packets"), 0u);  // a hole this long is a gap, not lost packets
  EXPECT_EQ(run.health.counters.at("partial_sweep"), 2);
  ASSERT_EQ(run.sweeps.size(), 2u);
  const StreamRun clean = feed(lidar, range(kPackets), streamConfig(lidar));
  EXPECT_EQ(run.sweeps[0].utime, clean.sweeps[0].utime);  // before the gap
  EXPECT_EQ(run.sweeps[1].utime, clean.sweeps[2].utime);  // after it
  EXPECT_EQ(run.sweeps[1].seq, 1);
}

TEST(LidarPacketStream, SingleLostPacketsAreCountedAndTheirSweepsKept) {
  SyntheticLidar lidar;
  const std::vector<int> lost = {50, 51, 90, 200, 202};  // a pair, single ones, two a packet apart
  std::vector<int> order;
  for (int k = 0; k < kPackets; ++k)
    if (std::find(lost.begin(), lost.end(), k) == lost.end()) order.push_back(k);
  const StreamRun run = feed(lidar, order, streamConfig(lidar));
  const StreamRun clean = feed(lidar, range(kPackets), streamConfig(lidar));
  EXPECT_EQ(run.health.counters.at("lost_packets"), 5);
  EXPECT_EQ(clean.health.counters.count("lost_packets"), 0u);
  EXPECT_EQ(run.health.counters.at("packet_gap"), 0);
  ASSERT_EQ(run.sweeps.size(), clean.sweeps.size());  // small holes: every sweep is still published
  for (std::size_t i = 0; i < run.sweeps.size(); ++i) EXPECT_EQ(run.sweeps[i].utime, clean.sweeps[i].utime);
}

TEST(SweepAssembler, StalledHeadPublishesNothing) {
  SyntheticLidar lidar;
  lidar.gap_centideg = 0;  // azimuth frozen: no cut ever
  const StreamRun run = feed(lidar, range(400), streamConfig(lidar));
  EXPECT_TRUE(run.sweeps.empty());
  EXPECT_GE(run.health.counters.at("sweep_too_long"), 1);
}

TEST(SweepAssembler, SweepsWithoutReturnsArePublishedEmpty) {
  SyntheticLidar lidar;
  lidar.no_return_fraction = 1.0;  // sensor blinded (covered window)
  const StreamRun run = feed(lidar, range(kPackets), streamConfig(lidar));
  ASSERT_EQ(run.sweeps.size(), 3u);
  for (const LidarScan& s : run.sweeps) EXPECT_TRUE(s.points.empty());
  EXPECT_EQ(run.health.counters.at("empty_sweep"), 3);
  EXPECT_NEAR((run.sweeps[1].utime - run.sweeps[0].utime) * 1e3, lidar.rotationNs(), 2000.0);
}

TEST(SweepAssembler, CutAngleMovesTheSeam) {
  SyntheticLidar lidar;
  LidarStreamConfig config = streamConfig(lidar);
  config.sweep.cut_azimuth_deg = 0.0;  // straight ahead
  const StreamRun run = feed(lidar, range(kPackets), config);
  const auto windows = truthWindows(lidar, kPackets, 0.0);
  ASSERT_EQ(run.sweeps.size(), windows.size() - 2);
  for (std::size_t j = 0; j < run.sweeps.size(); ++j) {
    const LidarScan& s = run.sweeps[j];
    ASSERT_FALSE(s.points.empty());
    // The last point of the sweep lies just right of straight ahead (azimuth just below 360).
    const LidarPoint& last = s.points.back();
    const double az = std::fmod(std::atan2(-last.p.y(), last.p.x()) * 180 / M_PI + 360.0, 360.0);
    EXPECT_GT(az, 359.0);
    EXPECT_EQ(s.points.size(), returnsIn(windows[j + 1]));
  }
}

}  // namespace
}  // namespace adit::drivers
