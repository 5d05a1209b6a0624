// Extending a saved map with a later session (issue 18, mode extend), on a synthetic straight roadway: the saved
// map holds 0-50 m; the session, in its own frame (turned and shifted), drove 30-80 m and was measured against the
// map on 30-45 m. The joined bundle must hold the session's new roadway at its true place in the map frame, drop
// the keyframes of roadway both hold, leave the saved map's points where they were, stay one connected graph and
// read back; a session never measured against the map, or of another sensor, is refused.
#include "core/geometry.hpp"
#include "loop/voxel_filter.hpp"
#include "map/bundle_extend.hpp"

#include <gtest/gtest.h>
#include <unistd.h>

#include <algorithm>
#include <filesystem>
#include <random>

namespace adit {
namespace {
namespace fs = std::filesystem;

constexpr std::int64_t kStart = 1700000000000000;

Eigen::Isometry3d along(double x) {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.translation() = Eigen::Vector3d(x, 0.0, 0.0);
  return T;
}

// What a lidar at any place of the roadway sees in its own frame: the two walls, 4 m apart, +-10 m along it.
std::vector<Eigen::Vector3f> wallsCloud(double x) {
  std::vector<Eigen::Vector3f> points;
  for (int i = 0; i <= 200; ++i)
    for (int h = 0; h < 5; ++h) {
      const float along_m = -10.0f + 0.1f * static_cast<float>(i), z = -1.0f + 0.5f * static_cast<float>(h);
      // A bump every 7 m of roadway (in the world) so that places differ.
      const float bump = std::fmod(static_cast<float>(x) + along_m + 1000.0f, 7.0f) < 0.5f ? 0.3f : 0.0f;
      points.emplace_back(along_m, 2.0f - bump, z);
      points.emplace_back(along_m, -2.0f, z);
    }
  return points;
}

const std::map<std::string, std::string> kConfig{{"features.preprocess.num_rings", "16"}, {"loop.scan_context.rings", "20"}};

// Keyframes every metre at x_from..x_to (map positions), at their poses in `frame` (T_frame_map).
MapBundle roadway(int x_from, int x_to, const Eigen::Isometry3d& T_frame_map, std::int64_t t0) {
  MapBundle b;
  VoxelAccumulator map(0.1);
  for (int x = x_from; x <= x_to; ++x) {
    const std::vector<Eigen::Vector3f> cloud = wallsCloud(x);
    BundleKeyframe k;
    k.utime = t0 + static_cast<std::int64_t>(x - x_from) * 1000000;
    k.pose = T_frame_map * along(x);
    k.cloud = CompactCloud::encode(cloud, 0.005f);
    k.context = ScanContext::build(cloud, ScanContextConfig{});
    b.graph.addNode(k.pose);
    if (!b.keyframes.empty())
      b.graph.addOdometryEdge(b.graph.size() - 2, b.graph.size() - 1, b.keyframes.back().pose.inverse() * k.pose,
                              Matrix6d::Identity() * 1e4);
    for (const Eigen::Vector3f& p : cloud) map.add((T_frame_map * along(x)).cast<float>() * p);
    b.keyframes.push_back(std::move(k));
  }
  b.map = map.centroids();
  b.config = kConfig;
  std::vector<Eigen::Vector3d> positions;
  for (const BundleKeyframe& k : b.keyframes) positions.push_back(k.pose.translation());
  b.summary = bundleSummaryOf(b.keyframes, 0.1, b.config, roadwayLength(positions));
  return b;
}

struct Sessions {
  MapBundle prior, session;
  Trajectory session_poses, anchors;
  Eigen::Isometry3d T_session_map;
};

Sessions sessions() {
  Sessions s;
  s.prior = roadway(0, 50, Eigen::Isometry3d::Identity(), kStart);
  s.T_session_map = Eigen::Isometry3d::Identity();
  s.T_session_map.linear() = Eigen::AngleAxisd(0.7, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  s.T_session_map.translation() = Eigen::Vector3d(5.0, -3.0, 0.5);
  const std::int64_t t0 = kStart + 3600000000LL;
  s.session = roadway(30, 80, s.T_session_map, t0);
  s.session.map.clear();
  // Sweeps 0.2 s (0.2 m) after each keyframe; the relocaliser measured those of 30-45 m, to within 2 cm.
  std::mt19937 random(7);
  std::normal_distribution<double> noise(0.0, 0.02);
  for (int x = 30; x <= 80; ++x) {
    const std::int64_t utime = t0 + static_cast<std::int64_t>(x - 30) * 1000000 + 200000;
    s.session_poses.push_back({utime, s.T_session_map * along(x + 0.2)});
    if (x > 45) continue;
    Eigen::Isometry3d measured = along(x + 0.2);
    measured.translation() += Eigen::Vector3d(noise(random), noise(random), noise(random));
    s.anchors.push_back({utime, measured});
  }
  return s;
}

TEST(BundleExtend, NewRoadwayJoinsTheMapAtItsTruePlaceAndMappedRoadwayIsKeptOnce) {
  const Sessions s = sessions();
  BundleExtendReport report;
  BundleExtendConfig config;
  config.overlap_radius = 2.5;  // keyframes 1 m apart: 52 m is 2 m from the saved 50 m, 53 m is 3 m from it
  config.hold_saved_map = true;
  const MapBundle both = extendBundle(s.prior, s.session, s.session_poses, s.anchors, config, &report);
  EXPECT_TRUE(report.solved);
  EXPECT_EQ(report.anchors_used, 16);
  // 30-52 m lie within 2.5 m of a saved keyframe (0-50 m): dropped; 53-80 m are new.
  EXPECT_EQ(report.overlap_keyframes, 23);
  EXPECT_EQ(report.kept_keyframes, 28);
  ASSERT_EQ(both.keyframes.size(), 51u + 28u);
  ASSERT_EQ(both.graph.size(), 79);
  for (int k = 0; k < 51; ++k) EXPECT_TRUE(both.keyframes[static_cast<std::size_t>(k)].pose.isApprox(s.prior.keyframes[static_cast<std::size_t>(k)].pose));
  double worst = 0.0, worst_deg = 0.0;
  for (std::size_t k = 51; k < both.keyframes.size(); ++k) {
    const double x = 53.0 + static_cast<double>(k - 51);
    const Eigen::Isometry3d error = along(x).inverse() * both.keyframes[k].pose;
    worst = std::max(worst, translationNorm(error));
    worst_deg = std::max(worst_deg, rotationAngle(error) * 180.0 / M_PI);
    EXPECT_TRUE(both.keyframes[k].pose.isApprox(both.graph.pose(static_cast<int>(k))));
  }
  // Anchors with 2 cm noise over 15 m, carried 35 m on exact odometry: a few centimetres, a small fraction of a degree.
  EXPECT_LT(worst, 0.08) << worst;
  EXPECT_LT(worst_deg, 0.2) << worst_deg;
  // One graph: the saved one, the new stretch's own edges, and one edge where it meets the map.
  EXPECT_EQ(report.junction_edges, 1);
  EXPECT_EQ(both.graph.edges().size(), s.prior.graph.edges().size() + 27u + 1u);
  // The saved map's points are all still there, unmoved; new points only beyond what it covered (x > 60 m).
  const auto inSavedPart = [](const std::vector<Eigen::Vector3f>& map) {
    return std::count_if(map.begin(), map.end(), [](const Eigen::Vector3f& p) { return p.x() < 59.5f; });
  };
  EXPECT_EQ(inSavedPart(both.map), inSavedPart(s.prior.map)) << "new points where the saved map already had some";
  EXPECT_GT(report.map_points_added, 1000u);
  for (const Eigen::Vector3f& p : s.prior.map) ASSERT_LE(p.x(), 60.05f);
  EXPECT_GT(std::count_if(both.map.begin(), both.map.end(), [](const Eigen::Vector3f& p) { return p.x() > 85.0f; }), 100);
  // The summary: both sessions' roadway, revisits counted once (50 m saved + 28 m new).
  EXPECT_NEAR(both.summary.roadway_length_m, 78.0, 1.5);
  EXPECT_EQ(both.summary.keyframes, 79);
  EXPECT_NEAR(both.summary.extent_max.x(), 80.0, 0.1);

  const fs::path dir = fs::temp_directory_path() / ("adit_bundle_extend_" + std::to_string(::getpid()));
  writeMapBundle(both, dir.string());
  const MapBundle loaded = loadMapBundle(dir.string());
  EXPECT_EQ(loaded.summary.keyframes, 79);
  EXPECT_EQ(loaded.graph.size(), 79);
  EXPECT_EQ(loadBundleMap(dir.string()).size(), both.map.size());
  fs::remove_all(dir);

  // Solved whole (the default): the maps agree, so the saved keyframes barely move (the anchors' 2 cm noise
  // against the saved graph's 1 cm edges) and the new roadway lands where it did.
  config.hold_saved_map = false;
  BundleExtendReport whole;
  const MapBundle solved = extendBundle(s.prior, s.session, s.session_poses, s.anchors, config, &whole);
  EXPECT_LT(whole.saved_moved_max_m, 0.03);
  ASSERT_EQ(solved.keyframes.size(), both.keyframes.size());
  for (std::size_t k = 51; k < solved.keyframes.size(); ++k)
    EXPECT_LT(translationNorm(along(53.0 + static_cast<double>(k - 51)).inverse() * solved.keyframes[k].pose), 0.1);
  // Redrawn from the keyframes' clouds at their solved poses: every point on a surface the saved map had.
  std::size_t off_surface = 0;
  for (const Eigen::Vector3f& p : solved.map) {
    if (p.x() >= 59.5f) continue;
    bool near = false;
    for (const Eigen::Vector3f& q : s.prior.map) near = near || (p - q).squaredNorm() < 0.15f * 0.15f;
    off_surface += near ? 0 : 1;
  }
  EXPECT_EQ(off_surface, 0u);
}

TEST(BundleExtend, ASessionNeverMeasuredAgainstTheMapOrOfAnotherSensorIsRefused) {
  Sessions s = sessions();
  const auto error = [&](const Trajectory& anchors) {
    try {
      extendBundle(s.prior, s.session, s.session_poses, anchors, BundleExtendConfig{});
    } catch (const BundleError& e) {
      return std::string(e.what());
    }
    return std::string();
  };
  EXPECT_NE(error({}).find("never relocalised"), std::string::npos) << error({});
  // Measured poses at no sweep of the session (100 s before it) tie nothing either.
  Trajectory elsewhere = s.anchors;
  for (StampedPose& p : elsewhere) p.utime -= 100000000;
  EXPECT_NE(error(elsewhere).find("never relocalised"), std::string::npos);
  s.session.config["features.preprocess.num_rings"] = "32";
  EXPECT_NE(error(s.anchors).find("sensor"), std::string::npos) << error(s.anchors);
}

}  // namespace
}  // namespace adit
