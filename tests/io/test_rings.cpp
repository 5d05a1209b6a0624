#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "io/kitti.hpp"
#include "io/rings.hpp"

namespace adit::io {
namespace {

constexpr double kDeg = M_PI / 180.0;
const std::string kRoot = std::string(ADIT_SHARED_DATA_DIR) + "/kitti_mini";

TEST(BeamTables, NominalAnglesAscendFromTheLowestBeam) {
  const auto vlp = vlp16Elevations();
  ASSERT_EQ(vlp.size(), 16u);
  EXPECT_NEAR(vlp.front(), -15 * kDeg, 1e-12);
  EXPECT_NEAR(vlp[8], 1 * kDeg, 1e-12);
  EXPECT_NEAR(vlp.back(), 15 * kDeg, 1e-12);
  EXPECT_EQ(rs16Elevations(), vlp);
  const auto hdl = hdl64Elevations();
  ASSERT_EQ(hdl.size(), 64u);
  EXPECT_NEAR(hdl.front(), -24.33 * kDeg, 1e-9);
  EXPECT_NEAR(hdl[31], -8.83 * kDeg, 1e-9);
  EXPECT_NEAR(hdl[32], -8.33 * kDeg, 1e-4);
  EXPECT_NEAR(hdl.back(), 2.0 * kDeg, 1e-9);
  for (size_t k = 1; k < hdl.size(); ++k) EXPECT_LT(hdl[k - 1], hdl[k]);
  EXPECT_EQ(beamTable("hdl64"), hdl);
  EXPECT_TRUE(beamTable("unknown").empty());
  EXPECT_EQ(uniformElevations(1, -0.1, 0.1), std::vector<double>{-0.1});
  EXPECT_TRUE(uniformElevations(0, -0.1, 0.1).empty());
}

TEST(RingsByElevation, RecoversEveryBeamOfASimulatedVlp16) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> azimuth(-M_PI, M_PI), range(1.0, 60.0), noise(-0.4 * kDeg, 0.4 * kDeg);
  const auto table = vlp16Elevations();
  std::vector<LidarPoint> points;
  std::vector<int> truth;
  for (int i = 0; i < 5000; ++i) {
    const int beam = i % 16;
    const double el = table[static_cast<size_t>(beam)] + noise(rng), az = azimuth(rng), r = range(rng);
    LidarPoint pt;
    pt.p = Eigen::Vector3f(static_cast<float>(r * std::cos(el) * std::cos(az)), static_cast<float>(r * std::cos(el) * std::sin(az)),
                           static_cast<float>(r * std::sin(el)));
    points.push_back(pt);
    truth.push_back(beam);
  }
  LidarPoint nan_point;
  nan_point.p = Eigen::Vector3f(NAN, 0, 0);
  points.push_back(nan_point);
  const RingAssignmentStats stats = assignRingsByElevation(points, table, 0.5 * kDeg);
  EXPECT_EQ(stats.invalid_points, 1);
  EXPECT_EQ(stats.far_from_beam, 0);
  for (size_t i = 0; i < truth.size(); ++i) ASSERT_EQ(points[i].ring, truth[i]) << i;
  for (int n : stats.per_ring) EXPECT_NEAR(n, 5000.0 / 16, 0.5);
}

TEST(RingsByElevation, UniformFanAndOutOfTablePoints) {
  const auto fan = uniformElevations(4, -3 * kDeg, 3 * kDeg);  // -3, -1, 1, 3 deg
  std::vector<LidarPoint> points(3);
  points[0].p = Eigen::Vector3f(10, 0, static_cast<float>(10 * std::tan(-1.2 * kDeg)));
  points[1].p = Eigen::Vector3f(0, 10, static_cast<float>(10 * std::tan(20 * kDeg)));  // far above the top beam
  points[2].p = Eigen::Vector3f(-10, 0, static_cast<float>(10 * std::tan(0.8 * kDeg)));
  const RingAssignmentStats stats = assignRingsByElevation(points, fan, 0.5 * kDeg);
  EXPECT_EQ(points[0].ring, 1);
  EXPECT_EQ(points[1].ring, 3);
  EXPECT_EQ(points[2].ring, 2);
  EXPECT_EQ(stats.far_from_beam, 1);
}

TEST(RingsByScanOrder, RefusesACloudWithTheWrongRowCount) {
  std::vector<LidarPoint> points;
  for (int row = 0; row < 3; ++row)
    for (int k = 0; k < 360; ++k) {
      LidarPoint pt;
      const double az = (k + 0.5) * kDeg;  // 0..360 deg counter-clockwise from the front
      pt.p = Eigen::Vector3f(static_cast<float>(std::cos(az)), static_cast<float>(std::sin(az)), 0.0f);
      pt.ring = 99;
      points.push_back(pt);
    }
  EXPECT_FALSE(assignRingsByScanOrder(points, 64));
  EXPECT_EQ(points[500].ring, 99);  // untouched
  ASSERT_TRUE(assignRingsByScanOrder(points, 3));
  EXPECT_EQ(points[0].ring, 2);  // first row stored is the top beam
  EXPECT_EQ(points[359].ring, 2);
  EXPECT_EQ(points[360].ring, 1);
  EXPECT_EQ(points.back().ring, 0);
}

// Every KITTI scan: 64 rings, all populated, ring 0 lowest, elevation rising ring by ring.
TEST(RingsByScanOrder, KittiMiniHasAllSixtyFourRingsInElevationOrder) {
  for (const char* name : {"00", "01", "02"}) {
    const KittiSequence seq = KittiSequence::open(kRoot, name);
    for (size_t i = 0; i < seq.size(); ++i) {
      KittiScanReport report;
      const LidarScan scan = seq.scan(i, &report);
      ASSERT_EQ(report.ring_method, KittiRingMethod::kScanOrder) << name << " scan " << i;
      std::vector<double> sum(64, 0.0);
      std::vector<int> count(64, 0);
      for (const LidarPoint& pt : scan.points) {
        ASSERT_LT(pt.ring, 64);
        sum[pt.ring] += std::atan2(pt.p.z(), std::hypot(pt.p.x(), pt.p.y()));
        ++count[pt.ring];
      }
      for (int r = 0; r < 64; ++r) ASSERT_GT(count[r], 500) << name << " scan " << i << " ring " << r;
      for (int r = 1; r < 64; ++r)
        EXPECT_GT(sum[r] / count[r], sum[r - 1] / count[r - 1]) << name << " scan " << i << " ring " << r;
      EXPECT_LT(sum[0] / count[0], -22 * kDeg) << name;  // HDL-64E: about -24.9 .. +2 deg
      EXPECT_GT(sum[63] / count[63], 1.5 * kDeg) << name;
    }
  }
}

}  // namespace
}  // namespace adit::io
