#include "sim/motion.hpp"

#include "sim/path.hpp"
#include "sim/rng.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

namespace adit::sim {
namespace {

constexpr double kDegToRad = M_PI / 180.0;
constexpr double kGridStep = 0.05;  // m, speed profile resolution along the path

// Speed along the path on a grid of kGridStep: forward/backward passes under acceleration limits.
std::vector<double> speedProfile(const Path2d& path, const MotionConfig& c, bool stop_at_end, Rng& rng) {
  const int n = std::max(1, static_cast<int>(std::ceil(path.length() / kGridStep)));
  const double l1 = rng.uniform(40.0, 90.0), l2 = rng.uniform(90.0, 200.0);
  const double p1 = rng.uniform(0.0, 2 * M_PI), p2 = rng.uniform(0.0, 2 * M_PI);
  std::vector<double> v(n + 1);
  for (int i = 0; i <= n; ++i) {
    const double s = path.length() * i / n;
    const double variation = 0.7 * std::sin(2 * M_PI * s / l1 + p1) + 0.3 * std::sin(2 * M_PI * s / l2 + p2);
    double limit = std::min(c.max_speed, c.cruise_speed * (1.0 + c.speed_variation * variation));
    // Corner limit, looked up slightly ahead and behind so the robot is slow for the whole arc.
    for (const double ds : {-0.3, 0.0, 0.3}) {
      const double k = std::fabs(path.at(s + ds).curvature);
      if (k > 1e-9) limit = std::min(limit, std::sqrt(c.lateral_accel / k));
    }
    v[i] = std::max(0.05, limit);
  }
  const double ds = path.length() / n;
  v[0] = 0.0;
  for (int i = 0; i < n; ++i) v[i + 1] = std::min(v[i + 1], std::sqrt(v[i] * v[i] + 2 * c.max_accel * ds));
  if (stop_at_end) v[n] = 0.0;
  for (int i = n; i > 0; --i) v[i - 1] = std::min(v[i - 1], std::sqrt(v[i] * v[i] + 2 * c.max_decel * ds));
  return v;
}

}  // namespace

MotionConfig motionConfigFrom(const adit::Config& cfg) {
  MotionConfig c;
  const std::string p = "sim.motion.";
  c.cruise_speed = cfg.get(p + "cruise_speed", c.cruise_speed);
  c.speed_variation = cfg.get(p + "speed_variation", c.speed_variation);
  c.max_speed = cfg.get(p + "max_speed", c.max_speed);
  c.max_accel = cfg.get(p + "max_accel", c.max_accel);
  c.max_decel = cfg.get(p + "max_decel", c.max_decel);
  c.lateral_accel = cfg.get(p + "lateral_accel", c.lateral_accel);
  c.corner_radius = cfg.get(p + "corner_radius", c.corner_radius);
  c.wander = cfg.get(p + "wander", c.wander);
  c.start_still = cfg.get(p + "start_still", c.start_still);
  c.mount_height = cfg.get(p + "mount_height", c.mount_height);
  c.track_length = cfg.get(p + "track_length", c.track_length);
  c.track_width = cfg.get(p + "track_width", c.track_width);
  c.vibration_deg = cfg.get(p + "vibration_deg", c.vibration_deg);
  c.bounce = cfg.get(p + "bounce", c.bounce);
  c.vibration_time = cfg.get(p + "vibration_time", c.vibration_time);
  c.knot_spacing = cfg.get(p + "knot_spacing", c.knot_spacing);
  return c;
}

double PlannedMotion::timeAtDistance(double metres) const {
  auto it = std::lower_bound(knot_distance.begin(), knot_distance.end(), metres);
  if (it == knot_distance.end()) return std::numeric_limits<double>::infinity();
  return knot_times[static_cast<std::size_t>(it - knot_distance.begin())];
}

PlannedMotion planMotion(const World& world, const MotionConfig& c, double duration, std::uint64_t seed) {
  Rng rng = Rng::forStream(seed, Stream::Motion);
  const double horizon = std::max(0.0, duration) + 1.0;

  // Route: repeat closed routes until they cover the horizon at full speed.
  std::vector<Eigen::Vector2d> waypoints = world.route;
  if (world.route_closed && world.route.size() > 2) {
    const double lap = std::max(1.0, world.routeLength());
    const int laps = 1 + static_cast<int>(std::ceil(horizon * c.max_speed / lap));
    for (int k = 1; k < laps; ++k) waypoints.insert(waypoints.end(), world.route.begin() + 1, world.route.end());
  }
  const Path2d path(waypoints, c.corner_radius);
  const std::vector<double> v = speedProfile(path, c, !world.route_closed, rng);
  const int n = static_cast<int>(v.size()) - 1;
  const double ds = path.length() / std::max(1, n);
  std::vector<double> t_grid(n + 1, 0.0);  // time to reach grid point i, from the end of the still period
  for (int i = 0; i < n; ++i) t_grid[i + 1] = t_grid[i] + 2 * ds / std::max(1e-6, v[i] + v[i + 1]);

  // Distance and speed at time t: constant acceleration within a grid cell (v^2 linear in s).
  auto distanceAt = [&](double t, double& speed) {
    t -= c.start_still;
    if (t <= 0.0 || n == 0) {
      speed = 0.0;
      return 0.0;
    }
    if (t >= t_grid[n]) {
      speed = v[n];
      return path.length() + v[n] * (t - t_grid[n]);
    }
    const int i = static_cast<int>(std::upper_bound(t_grid.begin(), t_grid.end(), t) - t_grid.begin()) - 1;
    const double a = (v[i + 1] * v[i + 1] - v[i] * v[i]) / (2 * ds), tau = t - t_grid[i];
    speed = v[i] + a * tau;
    return std::min(i * ds + v[i] * tau + 0.5 * a * tau * tau, (i + 1) * ds);
  };

  const double w1 = rng.uniform(20.0, 35.0), w2 = rng.uniform(45.0, 80.0);
  const double q1 = rng.uniform(0.0, 2 * M_PI), q2 = rng.uniform(0.0, 2 * M_PI);
  auto wander = [&](double s) {
    return c.wander * (0.6 * std::sin(2 * M_PI * s / w1 + q1) + 0.4 * std::sin(2 * M_PI * s / w2 + q2));
  };

  PlannedMotion out;
  out.route_length = path.length();
  const double dt = c.knot_spacing;
  const double t0 = 0.0;
  const int controls = static_cast<int>(std::ceil(horizon / dt)) + 4;
  const double rho = std::exp(-dt / std::max(1e-3, c.vibration_time)), innovation = std::sqrt(1 - rho * rho);
  Eigen::Vector4d vib = Eigen::Vector4d::Zero();  // pitch, roll, yaw, height: unit-variance AR(1) states
  std::vector<Eigen::Isometry3d> poses;
  poses.reserve(controls);
  for (int k = 0; k < controls; ++k) {
    const double t = t0 + (k - 1) * dt;
    double speed = 0.0;
    const double s = distanceAt(t, speed);
    const double s_path = std::min(s, path.length());
    const Path2d::Sample ps = path.at(s_path);
    const double offset = wander(s_path), slope = (wander(s_path + 0.05) - wander(s_path - 0.05)) / 0.1;
    const Eigen::Vector2d normal(-std::sin(ps.heading), std::cos(ps.heading));
    const Eigen::Vector2d xy = ps.position + offset * normal;
    const double yaw = ps.heading + std::atan(slope);

    // Attitude from the ground under the four track corners.
    const Eigen::Vector2d fwd(std::cos(yaw), std::sin(yaw)), left(-std::sin(yaw), std::cos(yaw));
    auto ground = [&](double f, double l) {
      const Eigen::Vector2d q = xy + f * fwd + l * left;
      return world.groundHeight(q.x(), q.y());
    };
    const double hl = c.track_length / 2, hw = c.track_width / 2;
    const double fl = ground(hl, hw), fr = ground(hl, -hw), rl = ground(-hl, hw), rr = ground(-hl, -hw);
    const double z_ground = 0.25 * (fl + fr + rl + rr);
    const double pitch_floor = -std::atan2(0.5 * (fl + fr - rl - rr), c.track_length);  // nose up = negative
    const double roll_floor = std::atan2(0.5 * (fl + rl - fr - rr), c.track_width);     // left up = positive

    for (int j = 0; j < 4; ++j) vib[j] = rho * vib[j] + innovation * rng.normal();
    const double scale = std::min(1.5, speed / 1.0);
    const double sigma = c.vibration_deg * kDegToRad * scale;
    const Eigen::Matrix3d R = (Eigen::AngleAxisd(yaw + sigma / 3 * vib[2], Eigen::Vector3d::UnitZ()) *
                               Eigen::AngleAxisd(pitch_floor + sigma * vib[0], Eigen::Vector3d::UnitY()) *
                               Eigen::AngleAxisd(roll_floor + sigma * vib[1], Eigen::Vector3d::UnitX()))
                                  .toRotationMatrix();
    Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
    T.linear() = R;
    T.translation() = Eigen::Vector3d(xy.x(), xy.y(), z_ground + c.bounce * scale * vib[3]) +
                      R * Eigen::Vector3d(0.0, 0.0, c.mount_height);
    poses.push_back(T);
    out.knot_times.push_back(t);
    out.knot_distance.push_back(s);
  }
  out.trajectory = BSplineTrajectory(t0, dt, std::move(poses));
  return out;
}

}  // namespace adit::sim
