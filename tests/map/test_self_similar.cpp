// The relocaliser's self-similarity test (map/relocaliser.hpp, reloc.refuse_self_similar) on synthetic
// room-and-pillar workings: square pillars on a 12 m grid, 6 m roadways, floor and roof. In the regular grid
// every place has twins, mapped or not, so a robot that starts outside the mapped part sees what it would see
// inside it: the map must be judged self-similar and every fix refused. With pillars of irregular size and
// position the map is judged distinct and a start inside it is fixed where it is.
#include "loop/voxel_filter.hpp"
#include "map/relocaliser.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <vector>

namespace adit {
namespace {

using Cloud = std::vector<Eigen::Vector3f>;

struct Pillar {
  double x0, x1, y0, y1;  // footprint
};

// The pillars within ~36 m of x: pillar (i, j) spans [12i + 3, 12i + 9] x [12j + 3, 12j + 9], so the roadways
// run along x = 12i and y = 12j and the grid goes on for ever. `irregular` moves and resizes each pillar by up
// to 2 m, the same way wherever it is asked for (seeded by the cell); the roadway along y = 0, where the robot
// drives, stays at least 4 m wide.
std::vector<Pillar> pillarsNear(double x, bool irregular) {
  std::vector<Pillar> out;
  const int centre = static_cast<int>(std::floor(x / 12.0));
  for (int i = centre - 3; i <= centre + 3; ++i)
    for (int j = -3; j <= 2; ++j) {
      Pillar p{12.0 * i + 3, 12.0 * i + 9, 12.0 * j + 3, 12.0 * j + 9};
      if (irregular) {
        std::mt19937 rng(static_cast<std::uint32_t>(1000 * (i + 100) + (j + 100)));
        std::uniform_real_distribution<double> jitter(-1.0, 1.0);
        p.x0 += 2.0 * jitter(rng);
        p.x1 += 2.0 * jitter(rng);
        const double y_shift = jitter(rng);  // towards or away from the y = 0 roadway, never into it
        if (j == 0) p.y0 += std::abs(y_shift);
        else if (j == -1) p.y1 -= std::abs(y_shift);
        else p.y0 += y_shift, p.y1 += y_shift;
      }
      out.push_back(p);
    }
  return out;
}

// What a lidar 1.2 m above the floor at `pose` (x, y, heading) sees within 20 m, in its own frame: pillar
// faces every 0.3 m, floor and roof (3.5 m) every 0.5 m; no occlusion (the map and the query are made alike).
Cloud view(bool irregular, double x, double y, double heading) {
  const std::vector<Pillar> world = pillarsNear(x, irregular);
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.translation() = Eigen::Vector3d(x, y, 1.2);
  T.linear() = Eigen::AngleAxisd(heading, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  const Eigen::Isometry3d inv = T.inverse();
  Cloud out;
  const double step = 0.3, floor_step = 0.5, reach = 20.0;
  const auto add = [&](double px, double py, double pz) {
    const Eigen::Vector3d p(px, py, pz);
    if ((p - T.translation()).head<2>().norm() < reach) out.push_back((inv * p).cast<float>());
  };
  const auto inside = [&](double px, double py) {
    for (const Pillar& p : world)
      if (px > p.x0 && px < p.x1 && py > p.y0 && py < p.y1) return true;
    return false;
  };
  for (double px = x - reach; px <= x + reach; px += floor_step)
    for (double py = y - reach; py <= y + reach; py += floor_step)
      if (!inside(px, py)) add(px, py, 0.0), add(px, py, 3.5);
  for (const Pillar& p : world) {
    for (double z = 0.0; z <= 3.5; z += step) {
      for (double px = p.x0; px <= p.x1; px += step) add(px, p.y0, z), add(px, p.y1, z);
      for (double py = p.y0; py <= p.y1; py += step) add(p.x0, py, z), add(p.x1, py, z);
    }
  }
  return out;
}

Eigen::Isometry3d pose2d(double x, double y, double heading) {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.translation() = Eigen::Vector3d(x, y, 1.2);
  T.linear() = Eigen::AngleAxisd(heading, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  return T;
}

// A bundle of a mapping drive along the y = 0 roadway from x = 0 to 48 m, a keyframe every metre.
MapBundle mapOf(bool irregular, const LoopCloserConfig& loop) {
  MapBundle bundle;
  for (int k = 0; k <= 48; ++k) {
    BundleKeyframe f;
    f.utime = k * 1000000LL;
    f.pose = pose2d(k, 0.0, 0.0);
    const Cloud cloud = voxelDownsample(view(irregular, k, 0.0, 0.0), loop.keyframe_voxel);
    f.context = keyframeScanContext(cloud, f.pose, loop.level_scan_context, loop.scan_context);
    f.cloud = CompactCloud::encode(cloud, static_cast<float>(loop.keyframe_cloud_step));
    bundle.keyframes.push_back(std::move(f));
  }
  return bundle;
}

RelocaliserConfig testConfig() {
  RelocaliserConfig config;
  config.self_similar_samples = 4;
  config.max_verifications = 2;
  config.submap_neighbors = 5;  // a small map of dense clouds: keep the ICP targets small
  config.submap_radius = 6.0;
  return config;
}

struct Standing {
  RelocStats stats;
  std::optional<Eigen::Isometry3d> fix;
};

// A robot standing for 6 s at (x, y, heading), relocalising in the map (told it starts near `start`, if given).
Standing standAt(bool irregular, double x, double y, double heading, bool refuse, const PoseHintConfig& start = {}) {
  LoopCloserConfig loop;
  RelocaliserConfig config = testConfig();
  config.refuse_self_similar = refuse;
  config.start = start;
  Relocaliser reloc(mapOf(irregular, loop), loop, config);
  const Cloud cloud = view(irregular, x, y, heading);
  Standing run;
  for (int i = 0; i <= 60 && !run.fix; ++i) {
    PoseEstimate session;
    session.utime = 100000000LL + i * 100000LL;
    const Relocaliser::Result r = reloc.process(session, cloud, false);
    if (r.T_map_lidar) run.fix = r.T_map_lidar;
  }
  run.stats = reloc.stats();
  return run;
}

TEST(SelfSimilarMap, ARegularPillarGridIsSelfSimilarIrregularPillarsAreNot) {
  const LoopCloserConfig loop;
  Relocaliser regular(mapOf(false, loop), loop, testConfig());
  EXPECT_TRUE(regular.mapSelfSimilar());
  EXPECT_EQ(regular.stats().self_similar_map, 1);
  EXPECT_EQ(regular.stats().self_similarity_checks, 4);
  Relocaliser irregular(mapOf(true, loop), loop, testConfig());
  EXPECT_FALSE(irregular.mapSelfSimilar());
  EXPECT_EQ(irregular.stats().self_similar_map, 0);
}

TEST(SelfSimilarMap, IrregularPillarsAreDistinctAndAStartInsideIsFixedWhereItIs) {
  const Standing run = standAt(true, 20.3, 0.2, 0.1, true);
  EXPECT_EQ(run.stats.self_similar_map, 0);
  ASSERT_TRUE(run.fix.has_value()) << run.stats.queries << " queries, " << run.stats.rejected_fit << " bad fits, "
                                   << run.stats.rejected_degenerate << " degenerate, " << run.stats.rejected_ambiguous
                                   << " ambiguous, " << run.stats.rejected_self_similar << " self-similar";
  EXPECT_LT((run.fix->translation() - pose2d(20.3, 0.2, 0.1).translation()).norm(), 0.3);
}

// In the regular grid every fix is refused (self-similar); told where it starts to within a few metres (the
// operator's start pose, 0.8 m and 6 deg off here) the robot is fixed where it is: no twin is that close.
// Told a place with no keyframe within its radius, it is not fixed at all.
TEST(SelfSimilarMap, AGivenStartPoseIsFixedInARegularGridOnlyNearIt) {
  PoseHintConfig start;
  start.given = true;
  start.x = 21.0, start.y = -0.3, start.z = 1.2, start.heading_deg = 12.0;
  const Standing run = standAt(false, 20.3, 0.2, 0.1, true, start);
  ASSERT_TRUE(run.fix.has_value()) << run.stats.queries << " queries, " << run.stats.hinted_queries << " near the start, "
                                   << run.stats.rejected_fit << " bad fits, " << run.stats.rejected_degenerate
                                   << " degenerate, " << run.stats.rejected_ambiguous << " ambiguous, "
                                   << run.stats.rejected_far_from_hint << " far from it";
  EXPECT_LT((run.fix->translation() - pose2d(20.3, 0.2, 0.1).translation()).norm(), 0.3);
  EXPECT_EQ(run.stats.rejected_self_similar, 0);
  EXPECT_GT(run.stats.hinted_queries, 0);

  start.x = 80.0;  // 32 m beyond the mapped 0-48 m
  const Standing outside = standAt(false, 20.3, 0.2, 0.1, true, start);
  EXPECT_FALSE(outside.fix.has_value());
  EXPECT_GT(outside.stats.hinted_queries, 0);
}

// Queries that find nothing (here: told a start outside the map, so no keyframe to verify) come less often:
// after every query_backoff_after of them the spacing doubles, up to query_backoff_max.
TEST(SelfSimilarMap, QueriesThatFindNothingBackOff) {
  const LoopCloserConfig loop;
  const Cloud cloud = view(true, 20.3, 0.2, 0.1);
  const auto queriesIn = [&](int backoff_after, double seconds) {
    RelocaliserConfig config = testConfig();
    config.refuse_self_similar = false;
    config.start.given = true;
    config.start.x = 80.0;
    config.query_backoff_after = backoff_after;
    config.query_backoff_max = 4.0;
    Relocaliser reloc(mapOf(true, loop), loop, config);
    for (int i = 0; i <= static_cast<int>(seconds * 10); ++i) {
      PoseEstimate session;
      session.utime = 100000000LL + i * 100000LL;
      reloc.process(session, cloud, false);
    }
    return reloc.stats().queries;
  };
  // Standing still, one query a second: 0, 1, then every 2 s (3, 5), then every 4 s (9, 13, 17) over 20 s.
  EXPECT_EQ(queriesIn(0, 20.0), 21);
  EXPECT_EQ(queriesIn(2, 20.0), 7);
}

}  // namespace
}  // namespace adit
