// Lidar model: geometry against the analytic roadway, beam layout, timing, and motion distortion.
#include "sim/lidar_model.hpp"
#include "sim/simulator.hpp"
#include "sim/world.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <map>

namespace adit::sim {
namespace {

constexpr double kDeg = M_PI / 180.0;

// A bare roadway: flat floor at z = 0, walls at y = +-2.25 up to 2.4 m, arch rising 0.6 m; nothing else.
World bareRoadway() {
  WorldConfig c = worldConfigFor("roadway-straight", 1);
  c.floor_roughness = c.wall_roughness = c.grade_amplitude = 0.0;
  c.support_arches = c.roof_bolts = c.services = c.equipment = c.side_cuts = false;
  return buildWorld(c);
}

PoseAt fixedPose(const Eigen::Isometry3d& T) {
  return [T](double) { return T; };
}

Eigen::Isometry3d at(double x, double y, double z) {
  return Eigen::Isometry3d(Eigen::Translation3d(x, y, z));
}

TEST(LidarProfile, BeamLayoutsOfTheRealSensors) {
  for (const char* name : {"vlp16", "rs16"}) {
    const LidarProfile p = lidarProfile(name);
    ASSERT_EQ(p.channels(), 16);
    const auto rings = p.rings();
    for (int j = 0; j < 16; ++j) EXPECT_DOUBLE_EQ(p.elevation_deg[j], -15.0 + 2.0 * rings[j]) << name;
    EXPECT_NEAR(360.0 / p.columns, 0.2, 0.002) << name;
    EXPECT_DOUBLE_EQ(p.rotation_hz, 10.0);
    EXPECT_DOUBLE_EQ(p.max_range, 100.0);
  }
  EXPECT_DOUBLE_EQ(lidarProfile("vlp16").elevation_deg[1], 1.0);   // interleaved firing order
  EXPECT_DOUBLE_EQ(lidarProfile("rs16").elevation_deg[8], 15.0);   // rs_driver channel order
  const LidarProfile hdl = lidarProfile("hdl64");
  ASSERT_EQ(hdl.channels(), 64);
  EXPECT_NEAR(*std::max_element(hdl.elevation_deg.begin(), hdl.elevation_deg.end()), 2.0, 1e-9);
  EXPECT_NEAR(*std::min_element(hdl.elevation_deg.begin(), hdl.elevation_deg.end()), -24.9, 1e-9);
  EXPECT_THROW(lidarProfile("ouster"), std::invalid_argument);
}

TEST(LidarGeometry, NoiselessCloudMatchesAnalyticRoadway) {
  const World world = bareRoadway();
  LidarNoiseConfig noise;
  noise.noiseless = true;
  const LidarSimulator lidar(lidarProfile("vlp16"), noise);
  const double h = 1.0;  // sensor height above the floor
  const LidarScan scan = lidar.simulate(world.scene, fixedPose(at(100.0, 0.3, h)), 1.0, 1000000, 0, 1);
  ASSERT_GT(scan.points.size(), 28000u);  // 1808 x 16 firings, all return inside a closed roadway
  const double half = 2.25, hw = 2.4, rise = 0.6;
  const double radius = (half * half + rise * rise) / (2 * rise), zc = hw + rise - radius;
  // The roof is the arch through the wall tops and the crown, tessellated in 6 chords.
  std::vector<Eigen::Vector2d> arch;
  const double phi0 = std::atan2(hw - zc, half);
  for (int k = 0; k <= 6; ++k) {
    const double phi = phi0 + (M_PI - 2 * phi0) * k / 6;
    arch.emplace_back(radius * std::cos(phi), zc + radius * std::sin(phi));
  }
  auto archDistance = [&](const Eigen::Vector2d& q) {
    double best = 1e9;
    for (int k = 0; k < 6; ++k) {
      const Eigen::Vector2d a = arch[k], b = arch[k + 1];
      const double s = std::clamp((q - a).dot(b - a) / (b - a).squaredNorm(), 0.0, 1.0);
      best = std::min(best, (a + s * (b - a) - q).norm());
    }
    return best;
  };
  int floor = 0, walls = 0, roof = 0;
  double worst = 0.0;
  for (const LidarPoint& p : scan.points) {
    const Eigen::Vector3d w = p.p.cast<double>() + Eigen::Vector3d(100.0, 0.3, h);
    // Elevation of each point is its ring's beam angle.
    const double elevation = std::atan2(p.p.z(), std::hypot(p.p.x(), p.p.y()));
    EXPECT_NEAR(elevation, (-15.0 + 2.0 * p.ring) * kDeg, 2e-6);
    // Distance to each analytic surface; the point must lie on one of them.
    const double d_floor = std::fabs(w.z()) + (std::fabs(w.y()) > half + 1e-3 ? 1.0 : 0.0);
    const double d_wall = std::fabs(std::fabs(w.y()) - half) + (w.z() > hw + 1e-3 || w.z() < -1e-3 ? 1.0 : 0.0);
    const double d_roof = archDistance({w.y(), w.z()});
    const double d = std::min({d_floor, d_wall, d_roof});
    worst = std::max(worst, d);
    EXPECT_LT(d, 1e-3) << w.transpose();
    floor += d == d_floor;
    walls += d == d_wall && d != d_floor;
    roof += d == d_roof && d != d_floor && d != d_wall;
  }
  std::printf("geometry: %zu points, floor %d walls %d roof %d, worst distance to the analytic section %.2e m\n",
              scan.points.size(), floor, walls, roof, worst);
  EXPECT_GT(floor, 1500);
  EXPECT_GT(walls, 15000);
  EXPECT_GT(roof, 1500);
}

TEST(LidarGeometry, RangeNoiseAndDropoutsAsConfigured) {
  const World world = bareRoadway();
  const LidarSimulator noisy(lidarProfile("vlp16"), LidarNoiseConfig{});
  LidarNoiseConfig exact_cfg;
  exact_cfg.noiseless = true;
  const LidarSimulator exact(lidarProfile("vlp16"), exact_cfg);
  const auto pose = fixedPose(at(100.0, 0.0, 1.0));
  const LidarScan a = noisy.simulate(world.scene, pose, 1.0, 1000000, 3, 9);
  const LidarScan b = exact.simulate(world.scene, pose, 1.0, 1000000, 3, 9);
  std::map<std::pair<int, float>, float> truth;  // (ring, dt) identifies a firing
  for (const LidarPoint& p : b.points) truth[{p.ring, p.dt}] = p.p.norm();
  double sum = 0, sum2 = 0;
  int n = 0;
  for (const LidarPoint& p : a.points) {
    const auto it = truth.find({p.ring, p.dt});
    ASSERT_NE(it, truth.end());
    const double e = p.p.norm() - it->second;
    sum += e;
    sum2 += e * e;
    ++n;
  }
  const double mean = sum / n, sigma = std::sqrt(sum2 / n - mean * mean);
  std::printf("range noise: mean %.2e m, sigma %.4f m over %d points, lost %.1f %%\n", mean, sigma, n,
              100.0 * (1.0 - static_cast<double>(a.points.size()) / b.points.size()));
  EXPECT_NEAR(mean, 0.0, 0.001);
  EXPECT_NEAR(sigma, 0.02, 0.002);  // profile range_sigma
  const double lost = 1.0 - static_cast<double>(a.points.size()) / b.points.size();
  EXPECT_GT(lost, 0.01);  // 1 % everywhere plus grazing and far dark returns
  EXPECT_LT(lost, 0.08);
}

TEST(LidarTiming, PerPointTimesRingsAndSpinLikeADriver) {
  const World world = bareRoadway();
  const LidarSimulator lidar(lidarProfile("vlp16"), LidarNoiseConfig{});
  const LidarScan scan = lidar.simulate(world.scene, fixedPose(at(50.0, 0.0, 1.0)), 2.0, 2000000, 7, 1);
  EXPECT_EQ(scan.utime, 2000000);
  EXPECT_EQ(scan.seq, 7);
  EXPECT_EQ(scan.num_beams, 16);
  EXPECT_TRUE(scan.has_ring && scan.has_time && !scan.deskewed);
  ASSERT_FALSE(scan.points.empty());
  float prev = -1.0f;
  for (const LidarPoint& p : scan.points) {
    EXPECT_GE(p.dt, -scan.sweep_duration);
    EXPECT_LE(p.dt, 0.0f);
    EXPECT_GE(p.dt, prev - 1e-7f);  // firing order
    prev = p.dt;
    EXPECT_LT(p.ring, 16);
  }
  EXPECT_GT(scan.points.front().dt, -0.1f);
  EXPECT_LT(scan.points.front().dt, -0.0999f);
  EXPECT_GT(scan.points.back().dt, -1e-4f);
  // The sweep starts behind the robot and spins clockwise: left side (+y) before the front, right side after.
  auto azimuth = [](const LidarPoint& p) { return std::atan2(p.p.y(), p.p.x()); };
  EXPECT_GT(std::fabs(azimuth(scan.points.front())), 179.0 * kDeg);
  const LidarPoint* quarter = &scan.points.front();
  for (const LidarPoint& p : scan.points)
    if (std::fabs(p.dt + 0.075f) < std::fabs(quarter->dt + 0.075f)) quarter = &p;
  EXPECT_NEAR(azimuth(*quarter), 90.0 * kDeg, 0.5 * kDeg);  // a quarter turn after the start
}

// Driving at v along x in a box room: each firing at dt happened v*|dt| further back, so a point it measures on
// the front or back wall has a sensor x larger by exactly v*|dt| than the same firing with motion frozen at the
// sweep's end (same noise draw, so noise cancels). Side walls, floor and ceiling are unchanged by this motion.
TEST(LidarDistortion, TranslationShiftsEachFiringByVelocityTimesDt) {
  Scene room;  // interior of a 40 x 10 x 5 m box
  const float X = 20, Y = 5, Zlo = -2, Zhi = 3;
  room.addQuad({X, -Y, Zlo}, {X, Y, Zlo}, {X, Y, Zhi}, {X, -Y, Zhi}, 0.5f);
  room.addQuad({-X, -Y, Zlo}, {-X, Y, Zlo}, {-X, Y, Zhi}, {-X, -Y, Zhi}, 0.5f);
  room.addQuad({-X, Y, Zlo}, {X, Y, Zlo}, {X, Y, Zhi}, {-X, Y, Zhi}, 0.5f);
  room.addQuad({-X, -Y, Zlo}, {X, -Y, Zlo}, {X, -Y, Zhi}, {-X, -Y, Zhi}, 0.5f);
  room.addQuad({-X, -Y, Zlo}, {X, -Y, Zlo}, {X, Y, Zlo}, {-X, Y, Zlo}, 0.5f);
  room.addQuad({-X, -Y, Zhi}, {X, -Y, Zhi}, {X, Y, Zhi}, {-X, Y, Zhi}, 0.5f);
  room.build();
  const double v = 1.5, t_end = 1.0;
  const PoseAt moving = [&](double t) { return at(v * (t - t_end), 0.0, 0.0); };
  const LidarSimulator lidar(lidarProfile("vlp16"), LidarNoiseConfig{});
  const LidarScan m = lidar.simulate(room, moving, t_end, 1000000, 4, 2);
  const LidarScan f = lidar.simulate(room, fixedPose(at(0, 0, 0)), t_end, 1000000, 4, 2);
  std::map<std::pair<int, float>, Eigen::Vector3f> frozen;
  for (const LidarPoint& p : f.points) frozen[{p.ring, p.dt}] = p.p;
  int compared = 0;
  double max_shift = 0.0, max_error = 0.0;
  for (const LidarPoint& p : m.points) {
    const auto it = frozen.find({p.ring, p.dt});
    // Firings on the front and back walls (the sweep starts and ends behind, so |dt| spans the whole sweep).
    if (it == frozen.end() || std::fabs(it->second.x()) < X - 0.2f || std::fabs(it->second.y()) > Y - 0.3f) continue;
    const double shift = p.p.x() - it->second.x(), expected = v * -p.dt;
    max_shift = std::max(max_shift, shift);
    max_error = std::max(max_error, std::fabs(shift - expected));
    ++compared;
  }
  std::printf("distortion: %d firings on the end walls, max shift %.4f m, max |shift - v|dt|| %.2e m\n", compared,
              max_shift, max_error);
  EXPECT_GT(compared, 1000);
  EXPECT_GT(max_shift, 0.14);   // up to v * 0.1 s = 15 cm at the seam behind: deskewing is needed
  EXPECT_LT(max_error, 2e-4);   // float precision at 20 m: the distortion is exactly the motion
}

// On a real run (vibrating, turning robot), every firing was cast from the pose at its own time: moving each
// point into the world with the ground-truth pose at its firing time lands it on the surface, while using the
// sweep-end pose for all points (no deskew) leaves errors of centimetres to decimetres.
TEST(LidarDistortion, RealRunFiringsUseThePoseAtTheirOwnTime) {
  SimConfig config;
  config.world = "room-and-pillar";  // turns at junctions every 20 m
  config.duration_s = 40.0;
  config.lidar.noiseless = true;
  const Simulator sim(config);
  // A sweep while turning through the first corner (yaw rate and speed non-zero).
  double best_t = 0, best_rate = 0;
  for (double t = 5.0; t < 39.0; t += 0.1) {
    const double rate = std::fabs(sim.trajectory().state(t).angular_velocity.z());
    if (rate > best_rate) best_rate = rate, best_t = t;
  }
  ASSERT_GT(best_rate, 0.2);
  const std::int64_t seq = static_cast<std::int64_t>(best_t * 10.0) - 1;
  const LidarScan scan = sim.simulateSweep(seq);
  const double t_end = sim.secondsOf(scan.utime);
  const Eigen::Isometry3d T_end = sim.trajectory().pose(t_end);
  double max_naive = 0.0, max_exact = 0.0;
  for (std::size_t i = 0; i < scan.points.size(); i += 7) {
    const LidarPoint& p = scan.points[i];
    const Eigen::Isometry3d T = sim.trajectory().pose(t_end + p.dt);
    // Exact: re-cast from the firing's own pose toward the point, the surface is at the measured range.
    Ray ray;
    ray.origin = T.translation().cast<float>();
    ray.dir = (T.linear() * p.p.cast<double>().normalized()).cast<float>();
    const Hit hit = sim.world().scene.intersect(ray);
    ASSERT_TRUE(hit.valid());
    max_exact = std::max(max_exact, std::fabs(double(hit.t) - p.p.norm()));
    max_naive = std::max(max_naive, ((T_end * p.p.cast<double>()) - (T * p.p.cast<double>())).norm());
  }
  std::printf("real run: max |recast - measured| %.2e m, max naive (no deskew) error %.3f m\n", max_exact, max_naive);
  EXPECT_LT(max_exact, 5e-4);  // interpolation inside 0.44 ms + float rounding (observed ~6e-5 m)
  EXPECT_GT(max_naive, 0.1);
}

TEST(LidarDust, DustAddsNearDarkReturns) {
  const World world = bareRoadway();
  LidarNoiseConfig dusty;
  dusty.dust = true;
  const LidarSimulator a(lidarProfile("vlp16"), LidarNoiseConfig{}), b(lidarProfile("vlp16"), dusty);
  auto nearDark = [](const LidarScan& s) {
    int n = 0;
    for (const LidarPoint& p : s.points) n += p.p.norm() < 2.0f && p.intensity < 10.0f;
    return n;
  };
  const auto pose = fixedPose(at(100.0, 0.0, 1.0));
  const int clean = nearDark(a.simulate(world.scene, pose, 1.0, 1000000, 0, 1));
  const int dust = nearDark(b.simulate(world.scene, pose, 1.0, 1000000, 0, 1));
  EXPECT_EQ(clean, 0);
  EXPECT_GT(dust, 250);  // 2 % of 29k firings, 66 % of them within 2 m: ~380
}

TEST(LidarBadInput, EmptySceneGivesEmptyScan) {
  Scene empty;
  empty.build();
  const LidarSimulator lidar(lidarProfile("rs16"), LidarNoiseConfig{});
  const LidarScan scan = lidar.simulate(empty, fixedPose(at(0, 0, 0)), 0.1, 100000, 0, 1);
  EXPECT_TRUE(scan.points.empty());
  EXPECT_EQ(scan.num_beams, 16);
}

}  // namespace
}  // namespace adit::sim
