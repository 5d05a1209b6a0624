// A VLP-32C capture of a room, imported as `adit import pcap --sensor vlp32c` does it (capture -> the live
// driver's stream -> compact sweeps on the bus -> decoded), then the feature stage configured with
// launch/config/pipeline.yaml + launch/sensors/vlp32c.yaml: all 32 rings arrive, sharp points are found on
// the room's edges (where two of its faces meet) and flat points on its faces away from the edges.
#include "features/feature_config.hpp"
#include "features/feature_extractor.hpp"
#include "msg/sweep_codec.hpp"
#include "pcap_recording.hpp"
#include "runtime/process.hpp"
#include "sources/pcap_source.hpp"

#include <gtest/gtest.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <set>

namespace adit::sources {
namespace {

using drivers::testing::Model;
using drivers::testing::SyntheticLidar;

// An axis-aligned room around the sensor, off centre so no two walls are at the same distance.
constexpr std::array<double, 3> kLow{-14.0, -5.0, -1.8}, kHigh{19.0, 7.0, 3.2};

double rangeInRoom(const Eigen::Vector3d& d) {
  double t = 1e9;
  for (int a = 0; a < 3; ++a) {
    if (d[a] > 1e-12) t = std::min(t, kHigh[a] / d[a]);
    if (d[a] < -1e-12) t = std::min(t, kLow[a] / d[a]);
  }
  return t;
}

// Distances of p to the room's six faces, nearest first.
std::array<double, 6> faceDistances(const Eigen::Vector3f& p) {
  std::array<double, 6> d{};
  for (int a = 0; a < 3; ++a) {
    d[2 * a] = std::abs(p[a] - kLow[a]);
    d[2 * a + 1] = std::abs(kHigh[a] - p[a]);
  }
  std::sort(d.begin(), d.end());
  return d;
}

TEST(PcapFeatures, Vlp32cRoomGivesEveryRingAndEdgesAndFlatsWhereTheyAre) {
  SyntheticLidar lidar;
  lidar.model = Model::kVlp32c;
  lidar.gap_centideg = 20;  // 0.2 deg per firing sequence: 10 Hz
  lidar.no_return_fraction = 0.0;
  lidar.scene = rangeInRoom;
  testing::Recording r;
  r.packets = static_cast<int>(2.6 * lidar.rotationNs() / static_cast<double>(lidar.packetNs()));
  const std::string path = ::testing::TempDir() + "adit_pcap_features_" + std::to_string(::getpid()) + ".pcap";
  {
    std::ofstream f(path, std::ios::binary);
    f << testing::writeRecording(lidar, r);
  }
  auto source = makePcapLidarSource(path, testing::configOf(lidar));
  const std::vector<LidarScan> sweeps = testing::publishedSweeps(*source);
  std::remove(path.c_str());
  ASSERT_EQ(sweeps.size(), 3u);  // one whole revolution between the first cut and the partial end
  const LidarScan& sweep = sweeps[1];
  ASSERT_FALSE(sweep.partial);
  testing::expectPointsMatchTruth(lidar, r, sweeps, {[](double range) { return msg::sweepTolerance(range, msg::kRangeScale); },
                                                     2500.0 + 0.5 * 0.1e9 / 65535});
  std::set<int> rings;
  for (const LidarPoint& p : sweep.points) rings.insert(p.ring);
  EXPECT_EQ(rings.size(), 32u);
  EXPECT_EQ(*rings.rbegin(), 31);

  const std::string launch = std::string(ADIT_SOURCE_DIR) + "/launch/";
  const FeatureConfig config =
      featureConfigFrom(runtime::loadConfig({launch + "config/pipeline.yaml", launch + "sensors/vlp32c.yaml"}));
  ASSERT_EQ(config.preprocess.num_rings, 32);
  const FeatureSet f = FeatureExtractor(config).process(sweep, {}, MotionPrior{});
  EXPECT_EQ(f.flags & (FeatureSet::kEmptySweep | FeatureSet::kEmptyRing), 0);
  ASSERT_GT(f.corner_sharp.size(), 10u);
  ASSERT_GT(f.surf_flat.size(), 200u);
  // An edge point is near two faces; a flat point lies on one face, away from the others. "Near" is a couple
  // of point spacings on a far wall seen at a grazing angle (0.2 deg at 19.7 m on a wall 15 deg off the beam:
  // 27 cm between points), and the sweep's points that near an edge are few, so the fractions below mean
  // something.
  constexpr double kNearEdge = 0.5;
  const auto near_edge = [](const LidarPoint& p) { return faceDistances(p.p)[1] < kNearEdge; };
  const auto all_near = std::count_if(sweep.points.begin(), sweep.points.end(), near_edge);
  const auto sharp_near = std::count_if(f.corner_sharp.begin(), f.corner_sharp.end(), near_edge);
  const auto flat_on_face = std::count_if(f.surf_flat.begin(), f.surf_flat.end(), [](const LidarPoint& p) {
    const auto d = faceDistances(p.p);
    return d[0] < 0.01 && d[1] > 0.1;
  });
  std::printf("sweep: %zu points (%ld within %.1f m of an edge); sharp %zu (%ld near an edge), flat %zu (%ld on a "
              "face, > 0.1 m from the next)\n", sweep.points.size(), static_cast<long>(all_near), kNearEdge,
              f.corner_sharp.size(), static_cast<long>(sharp_near), f.surf_flat.size(), static_cast<long>(flat_on_face));
  EXPECT_LT(static_cast<double>(all_near), 0.2 * static_cast<double>(sweep.points.size()));
  EXPECT_GE(static_cast<double>(sharp_near), 0.95 * static_cast<double>(f.corner_sharp.size()));
  EXPECT_GE(static_cast<double>(flat_on_face), 0.95 * static_cast<double>(f.surf_flat.size()));
}

}  // namespace
}  // namespace adit::sources
