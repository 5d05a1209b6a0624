// Compact sweeps (lidar_scan_t): every sensor's sweep decodes back within the sensor's resolution, in the same
// order, with the same rings and times; sources without a firing grid use the per-point layout; messages that
// do not fit their profile, or of an unknown version, are refused with a reason; old point_cloud_t still reads.
#include "io/kitti.hpp"
#include "msg/convert.hpp"
#include "msg/encode.hpp"
#include "msg/sweep_codec.hpp"
#include "nodes/registry.hpp"
#include "sim_sweeps.hpp"

#include <gtest/gtest.h>

#include <filesystem>

namespace adit {
namespace {

struct Fidelity {
  double worst_m = 0, worst_dt_s = 0;
  std::size_t bytes = 0;
};

Fidelity roundTrip(const LidarScan& in, const adit::lidar_scan_t& m) {
  Fidelity f;
  f.bytes = static_cast<std::size_t>(m.getEncodedSize());
  adit::lidar_scan_t back;
  const std::vector<std::uint8_t> bytes = msg::encode(m);
  EXPECT_EQ(back.decode(bytes.data(), 0, static_cast<int>(bytes.size())), static_cast<int>(bytes.size()));
  LidarScan out;
  EXPECT_EQ(msg::decodeSweep(back, out), "");
  EXPECT_EQ(out.utime, in.utime);
  EXPECT_EQ(out.seq, in.seq);
  EXPECT_EQ(out.sensor, in.sensor);
  EXPECT_EQ(out.num_beams, in.num_beams);
  EXPECT_EQ(out.has_ring, in.has_ring);
  EXPECT_EQ(out.has_time, in.has_time);
  EXPECT_FLOAT_EQ(out.sweep_duration, in.sweep_duration);
  EXPECT_EQ(out.points.size(), in.points.size());
  if (out.points.size() != in.points.size()) return f;
  for (std::size_t i = 0; i < in.points.size(); ++i) {
    const LidarPoint &a = in.points[i], &b = out.points[i];
    const double err = (a.p - b.p).norm();
    f.worst_m = std::max(f.worst_m, err);
    f.worst_dt_s = std::max(f.worst_dt_s, static_cast<double>(std::fabs(a.dt - b.dt)));
    EXPECT_LE(err, msg::sweepTolerance(a.p.norm(), m.range_scale)) << "point " << i;
    if (in.has_ring) {
      EXPECT_EQ(a.ring, b.ring) << "point " << i;
    }
    EXPECT_NEAR(a.intensity, b.intensity, 0.5 * m.intensity_scale + 1e-6) << "point " << i;
  }
  return f;
}

class SensorSweeps : public ::testing::TestWithParam<const char*> {};

TEST_P(SensorSweeps, GridLayoutDecodesWithinTheSensorResolution) {
  const test::SimSweeps s = test::simulateSweeps(GetParam(), 3);
  ASSERT_EQ(s.sweeps.size(), 3u);
  for (const LidarScan& scan : s.sweeps) {
    const adit::lidar_scan_t m = msg::encodeSweep(scan, &s.table);
    ASSERT_EQ(m.layout, +adit::lidar_scan_t::LAYOUT_GRID) << GetParam();
    const Fidelity f = roundTrip(scan, m);
    // Half a range count (1 mm) at any range: the azimuth of a column is kept to 2 pi / 2^32.
    EXPECT_LE(f.worst_m, 0.5 * m.range_scale + 1e-4);
    // Firing times survive to float rounding of the original (a few ns): deskewing sees no difference.
    EXPECT_LT(f.worst_dt_s, 2e-8);
    const std::size_t full = static_cast<std::size_t>(msg::toMessage(scan).getEncodedSize());
    std::printf("%s: %zu points, %zu columns, %zu bytes compact vs %zu full (%.1fx), worst error %.2f mm\n",
                GetParam(), scan.points.size(), static_cast<std::size_t>(m.num_columns), f.bytes, full,
                static_cast<double>(full) / static_cast<double>(f.bytes), f.worst_m * 1e3);
    // 3 bytes a firing + 8 a column: at most a sixth of the full-float form at the simulator's few dropouts.
    EXPECT_LT(f.bytes * 5, full);
    // Encoding is a pure function of the sweep.
    EXPECT_EQ(msg::encode(m), msg::encode(msg::encodeSweep(scan, &s.table)));
  }
}

INSTANTIATE_TEST_SUITE_P(Sensors, SensorSweeps, ::testing::Values("vlp16", "rs16", "hdl64"));

TEST(SweepCodec, AWrongFiringTableFallsBackToThePointLayout) {
  const test::SimSweeps s = test::simulateSweeps("vlp16", 1);
  msg::FiringTable wrong = s.table;
  for (auto& o : wrong.ring_offset_ns) o = 3 * o + 5000;  // not this head's timing
  const adit::lidar_scan_t m = msg::encodeSweep(s.sweeps[0], &wrong);
  EXPECT_EQ(m.layout, +adit::lidar_scan_t::LAYOUT_POINTS);
  const Fidelity f = roundTrip(s.sweeps[0], m);
  // Per point: sweep_duration / 65535 time steps.
  EXPECT_LT(f.worst_dt_s, 1e-6);
}

TEST(SweepCodec, KittiSweepUsesThePointLayoutWithinTolerance) {
  const std::string seq = std::string(ADIT_SHARED_DATA_DIR) + "/kitti_mini/sequences/01";
  if (!std::filesystem::exists(seq)) GTEST_SKIP() << "no kitti_mini at " << seq;
  const LidarScan scan = io::KittiSequence(seq).scan(0);
  const adit::lidar_scan_t m = msg::encodeSweep(scan, nullptr);
  EXPECT_EQ(m.layout, +adit::lidar_scan_t::LAYOUT_POINTS);
  const Fidelity f = roundTrip(scan, m);
  const std::size_t full = static_cast<std::size_t>(msg::toMessage(scan).getEncodedSize());
  std::printf("kitti: %zu points, %zu bytes compact vs %zu full, worst error %.2f mm\n", scan.points.size(), f.bytes,
              full, f.worst_m * 1e3);
  EXPECT_LT(f.bytes * 2, full);
}

TEST(SweepCodec, MessagesThatDoNotFitTheirProfileAreRefusedWithAReason) {
  const test::SimSweeps s = test::simulateSweeps("vlp16", 1);
  const adit::lidar_scan_t good = msg::encodeSweep(s.sweeps[0], &s.table);
  LidarScan out;
  ASSERT_EQ(msg::decodeSweep(good, out), "");

  adit::lidar_scan_t m = good;
  m.format_version = 2;
  EXPECT_NE(msg::decodeSweep(m, out).find("format_version 2"), std::string::npos);

  m = good;  // a VLP-16 has 16 beams
  m.num_beams = 32;
  m.ring_elevation.resize(32);
  m.ring_offset_ns.resize(32);
  m.num_columns /= 2;
  m.column_azimuth.resize(static_cast<std::size_t>(m.num_columns));
  m.column_time_ns.resize(static_cast<std::size_t>(m.num_columns));
  EXPECT_NE(msg::decodeSweep(m, out).find("beams"), std::string::npos);

  m = good;  // returns that are not columns x beams
  m.num_returns -= 1;
  m.range.pop_back();
  m.intensity.pop_back();
  EXPECT_NE(msg::decodeSweep(m, out), "");

  m = good;  // a firing index far outside the sweep
  m.column_time_ns[5] = -900'000'000;
  EXPECT_NE(msg::decodeSweep(m, out).find("outside the sweep"), std::string::npos);

  m = good;
  m.ring_offset_ns[3] = -1;
  EXPECT_NE(msg::decodeSweep(m, out).find("firing offset"), std::string::npos);

  m = good;
  m.range_scale = 0.0f;
  EXPECT_NE(msg::decodeSweep(m, out).find("range_scale"), std::string::npos);

  m = msg::encodeSweep(s.sweeps[0], nullptr);  // per-point layout: a ring beyond the profile's beams
  m.ring[0] = 16;
  EXPECT_NE(msg::decodeSweep(m, out).find("ring 16"), std::string::npos);
}

TEST(SweepCodec, SweepMessageReadsBothFormatsAndFlagsBadOnes) {
  const test::SimSweeps s = test::simulateSweeps("vlp16", 1);
  const LidarScan& scan = s.sweeps[0];
  msg::SweepMessage full;
  const std::vector<std::uint8_t> full_bytes = msg::encode(msg::toMessage(scan));
  ASSERT_EQ(full.decode(full_bytes.data(), 0, static_cast<int>(full_bytes.size())), static_cast<int>(full_bytes.size()));
  EXPECT_FALSE(full.compact);
  EXPECT_EQ(full.error, "");
  EXPECT_EQ(full.scan.points.size(), scan.points.size());
  EXPECT_EQ(full.header.utime, scan.utime);

  msg::SweepMessage compact;
  adit::lidar_scan_t m = msg::encodeSweep(scan, &s.table);
  std::vector<std::uint8_t> bytes = msg::encode(m);
  ASSERT_GT(compact.decode(bytes.data(), 0, static_cast<int>(bytes.size())), 0);
  EXPECT_TRUE(compact.compact);
  EXPECT_EQ(compact.error, "");
  EXPECT_EQ(compact.scan.points.size(), scan.points.size());

  m.format_version = 7;
  bytes = msg::encode(m);
  ASSERT_GT(compact.decode(bytes.data(), 0, static_cast<int>(bytes.size())), 0);
  EXPECT_TRUE(compact.unknown_version);
  EXPECT_NE(compact.error.find("format_version 7"), std::string::npos);

  // Truncated bytes, or another type, are undecodable (-1), never a throw.
  EXPECT_LT(compact.decode(bytes.data(), 0, static_cast<int>(bytes.size() / 2)), 0);
  const std::vector<std::uint8_t> imu = msg::encode(msg::toMessage(ImuSample{}));
  EXPECT_LT(compact.decode(imu.data(), 0, static_cast<int>(imu.size())), 0);
}

TEST(SweepCodec, EmptyAndNonFiniteSweepsEncode) {
  LidarScan empty;
  empty.sensor = "vlp16";
  empty.num_beams = 16;
  LidarScan out;
  const adit::lidar_scan_t m = msg::encodeSweep(empty, nullptr);
  EXPECT_EQ(msg::decodeSweep(m, out), "");
  EXPECT_TRUE(out.points.empty());

  test::SimSweeps s = test::simulateSweeps("vlp16", 1);
  const std::size_t n = s.sweeps[0].points.size();
  s.sweeps[0].points[10].p.x() = std::numeric_limits<float>::quiet_NaN();
  const adit::lidar_scan_t with_nan = msg::encodeSweep(s.sweeps[0], &s.table);
  EXPECT_EQ(msg::decodeSweep(with_nan, out), "");
  EXPECT_EQ(out.points.size(), n - 1);  // the NaN point is left out, the rest keeps the grid
  EXPECT_EQ(with_nan.layout, +adit::lidar_scan_t::LAYOUT_GRID);
}

}  // namespace
}  // namespace adit

namespace adit {
namespace {

class CollectingSink : public runtime::Sink {
 public:
  void publish(const std::string& channel, const runtime::Bytes&, std::int64_t) override { channels.push_back(channel); }
  std::vector<std::string> channels;
};

TEST(FeatureNode, ReadsBothSweepFormatsAndCountsCompactSweepsThatDoNotFit) {
  const test::SimSweeps s = test::simulateSweeps("vlp16", 4);
  auto node = nodes::makeNode("feature", Config{});
  CollectingSink sink;
  const auto deliver = [&](const std::vector<std::uint8_t>& bytes) {
    node->deliver("LIDAR_POINTS", bytes.data(), bytes.size(), sink);
  };
  deliver(msg::encode(msg::toMessage(s.sweeps[0])));             // today's full-float format
  deliver(msg::encode(msg::encodeSweep(s.sweeps[1], &s.table)));  // compact
  adit::lidar_scan_t future = msg::encodeSweep(s.sweeps[2], &s.table);
  future.format_version = 2;
  deliver(msg::encode(future));
  adit::lidar_scan_t misfit = msg::encodeSweep(s.sweeps[3], &s.table);
  misfit.column_time_ns[0] = -800'000'000;  // a column far before the sweep
  deliver(msg::encode(misfit));
  EXPECT_EQ(sink.channels, (std::vector<std::string>{"FEATURES", "FEATURES"}));
  const runtime::Health& h = node->health();
  EXPECT_EQ(h.counters.at("unknown_format_version"), 1);
  EXPECT_EQ(h.counters.at("invalid_sweep"), 1);
  EXPECT_EQ(h.errors, 2);
  EXPECT_NE(h.last_error.find("outside the sweep"), std::string::npos) << h.last_error;
}

}  // namespace
}  // namespace adit
