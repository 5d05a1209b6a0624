// KITTI-layout folders written from heads other than the HDL-64E: the beam count detected from a scan (scan
// order, else the elevation histogram) and every point's ring, for 16-, 32- and 128-beam fans, in KITTI's
// beam-by-beam order and shuffled (no order to go by).
#include "io/kitti.hpp"
#include "io/rings.hpp"
#include "temp_dir.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <random>

namespace adit::io {
namespace {

namespace fs = std::filesystem;
using test::TempDir;

std::vector<double> fan(int beams, double low_deg, double high_deg) {
  std::vector<double> e;
  for (int i = 0; i < beams; ++i) e.push_back(low_deg + (high_deg - low_deg) * i / (beams - 1));
  return e;
}

// A sweep of a wavy wall (range 8..14 m), beam by beam, top beam first, each row from the front
// counter-clockwise once around (KITTI's layout); `shuffled` mixes every point of the file.
std::vector<LidarPoint> sweep(const std::vector<double>& elevations_deg, int columns, bool shuffled) {
  std::vector<LidarPoint> points;
  for (int b = static_cast<int>(elevations_deg.size()) - 1; b >= 0; --b) {
    const double e = elevations_deg[static_cast<std::size_t>(b)] * M_PI / 180.0;
    for (int c = 0; c < columns; ++c) {
      double az = 1e-3 + 2 * M_PI * c / columns;
      if (az > M_PI) az -= 2 * M_PI;
      const double r = 11.0 + 3.0 * std::sin(3 * az);
      LidarPoint p;
      p.p = Eigen::Vector3d(r * std::cos(e) * std::cos(az), r * std::cos(e) * std::sin(az), r * std::sin(e)).cast<float>();
      p.ring = static_cast<std::uint16_t>(b);  // the truth, overwritten by the reader
      points.push_back(p);
    }
  }
  if (shuffled) std::shuffle(points.begin(), points.end(), std::mt19937(3));
  return points;
}

std::string binOf(const std::vector<LidarPoint>& points) {
  std::string bytes;
  for (const LidarPoint& p : points) {
    const float v[4] = {p.p.x(), p.p.y(), p.p.z(), 0.5f};
    bytes.append(reinterpret_cast<const char*>(v), sizeof v);
  }
  return bytes;
}

struct Case {
  const char* name;
  std::vector<double> elevations_deg;
  bool shuffled;
  KittiRingMethod method;
};

class KittiBeams : public ::testing::TestWithParam<Case> {};

TEST_P(KittiBeams, DetectedAndEveryRingRight) {
  const Case& c = GetParam();
  const auto truth = sweep(c.elevations_deg, 900, c.shuffled);
  const int beams = static_cast<int>(c.elevations_deg.size());
  EXPECT_EQ(detectBeamCount(truth), beams);
  TempDir dir;
  fs::create_directories(dir.file("velodyne"));
  dir.write("times.txt", "1.0\n");
  dir.write("velodyne/000000.bin", binOf(truth));
  KittiSequence seq(dir.path());
  seq.setNumBeams(beams);
  KittiScanReport report;
  const LidarScan scan = seq.scan(0, &report);
  EXPECT_EQ(report.ring_method, c.method);
  EXPECT_EQ(scan.num_beams, beams);
  EXPECT_EQ(scan.sensor, "");
  ASSERT_EQ(scan.points.size(), truth.size());
  std::size_t wrong = 0;
  for (std::size_t i = 0; i < truth.size(); ++i) wrong += scan.points[i].ring != truth[i].ring;
  EXPECT_EQ(wrong, 0u);
}

// VLP-16 (-15..15 by 2), HDL-32E (-30.67..10.67 by 1.33), VLP-32C's uneven fan (dense near the horizon) and a
// 128-beam fan of 0.3 deg (scan order only: its beams are too close for the histogram).
INSTANTIATE_TEST_SUITE_P(
    Fans, KittiBeams,
    ::testing::Values(Case{"b16_scan_order", fan(16, -15, 15), false, KittiRingMethod::kScanOrder},
                      Case{"b16_shuffled", fan(16, -15, 15), true, KittiRingMethod::kElevationPeaks},
                      Case{"hdl32_shuffled", fan(32, -30.67, 10.67), true, KittiRingMethod::kElevationPeaks},
                      Case{"vlp32c_shuffled",
                           {-25, -15.639, -11.31, -8.843, -7.254, -6.148, -5.333, -4.667, -4, -3.667, -3.333, -3,
                            -2.667, -2.333, -2, -1.667, -1.333, -1, -0.667, -0.333, 0, 0.333, 0.667, 1, 1.333, 1.667,
                            2.333, 3.333, 4.667, 7, 10.333, 15},
                           true, KittiRingMethod::kElevationPeaks},
                      Case{"b128_scan_order", fan(128, -25, 13.1), false, KittiRingMethod::kScanOrder}),
    [](const auto& info) { return std::string(info.param.name); });

TEST(KittiBeams, KittiItselfIsDetectedAsSixtyFour) {
  const KittiSequence seq(std::string(ADIT_SHARED_DATA_DIR) + "/kitti_mini/sequences/00");
  EXPECT_EQ(detectBeamCount(readKittiBin(seq.scanFiles().front())), 64);
}

TEST(KittiBeams, ABeamCountOutOfRangeIsRefused) {
  TempDir dir;
  fs::create_directories(dir.file("velodyne"));
  dir.write("times.txt", "1.0\n");
  KittiSequence seq(dir.path());
  EXPECT_THROW(seq.setNumBeams(0), std::invalid_argument);
  EXPECT_THROW(seq.setNumBeams(300), std::invalid_argument);
}

}  // namespace
}  // namespace adit::io
