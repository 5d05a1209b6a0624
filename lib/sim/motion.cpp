#include "sim/motion.hpp"

#include "sim/path.hpp"
#include "sim/rng.hpp"

#include <algorithm>
#include <array>
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
  c.vibration_min_hz = cfg.get(p + "vibration_min_hz", c.vibration_min_hz);
  c.vibration_max_hz = cfg.get(p + "vibration_max_hz", c.vibration_max_hz);
  c.knot_spacing = cfg.get(p + "knot_spacing", c.knot_spacing);
  c.smoothing_window = cfg.get(p + "smoothing_window", c.smoothing_window);
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
  // The smoothing below reaches smoothing_window back in time: start the plan that much later so the robot is
  // exactly still for start_still seconds.
  const double motion_start = c.start_still + std::max(0.0, c.smoothing_window);
  auto distanceAt = [&](double t, double& speed) {
    t -= motion_start;
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
  out.lap_length = Path2d(world.route, c.corner_radius).length();
  const double dt = c.knot_spacing;
  const double t0 = 0.0;
  const int controls = static_cast<int>(std::ceil(horizon / dt)) + 4;
  // Vibration: per axis (pitch, roll, yaw, height) 3 sinusoids, unit RMS in total.
  struct Tone {
    double omega, phase, amplitude;
  };
  std::array<std::array<Tone, 3>, 4> tones;
  const double f_lo = std::max(0.05, c.vibration_min_hz), f_hi = std::max(f_lo, c.vibration_max_hz);
  for (auto& axis : tones) {
    double power = 0.0;
    for (Tone& tone : axis) {
      const double f = f_lo * std::pow(f_hi / f_lo, rng.uniform());
      tone = {2 * M_PI * f, rng.uniform(0.0, 2 * M_PI), 1.0 / f};
      power += 0.5 * tone.amplitude * tone.amplitude;
    }
    for (Tone& tone : axis) tone.amplitude /= std::sqrt(power);
  }
  auto vibration = [&](int axis, double t) {
    double sum = 0.0;
    for (const Tone& tone : tones[axis]) sum += tone.amplitude * std::sin(tone.omega * t + tone.phase);
    return sum;
  };
  std::vector<Eigen::Isometry3d> poses;
  poses.reserve(controls);
  // Pass 1: planar pose along the path (with wander) at every knot; heading unwrapped.
  std::vector<double> xs(controls), ys(controls), yaws(controls), speeds(controls), dists(controls);
  for (int k = 0; k < controls; ++k) {
    const double t = t0 + (k - 1) * dt;
    dists[k] = distanceAt(t, speeds[k]);
    const double s_path = std::min(dists[k], path.length());
    const Path2d::Sample ps = path.at(s_path);
    const double offset = wander(s_path), slope = (wander(s_path + 0.05) - wander(s_path - 0.05)) / 0.1;
    const Eigen::Vector2d xy = ps.position + offset * Eigen::Vector2d(-std::sin(ps.heading), std::cos(ps.heading));
    xs[k] = xy.x();
    ys[k] = xy.y();
    yaws[k] = ps.heading + std::atan(slope);
    if (k > 0) yaws[k] = yaws[k - 1] + std::remainder(yaws[k] - yaws[k - 1], 2 * M_PI);
  }
  // Pass 2: a real vehicle cannot jump in curvature or acceleration (arcs start abruptly on the geometric path):
  // smooth the planar motion with two passes of a centred moving average over smoothing_window seconds.
  const int half_window = std::max(0, static_cast<int>(std::lround(0.5 * c.smoothing_window / dt)));
  for (std::vector<double>* series : {&xs, &ys, &yaws}) {
    for (int pass = 0; pass < 2 && half_window > 0; ++pass) {
      std::vector<double> prefix(controls + 1, 0.0);
      for (int k = 0; k < controls; ++k) prefix[k + 1] = prefix[k] + (*series)[k];
      std::vector<double> out(controls);
      for (int k = 0; k < controls; ++k) {
        const int lo = std::max(0, k - half_window), hi = std::min(controls - 1, k + half_window);
        const int w = std::min(k - lo, hi - k);  // symmetric window, shrinking at the ends
        out[k] = (prefix[k + w + 1] - prefix[k - w]) / (2 * w + 1);
      }
      *series = out;
    }
  }
  // Pass 3: height and attitude from the floor, vibration, lidar on its mast.
  for (int k = 0; k < controls; ++k) {
    const double t = t0 + (k - 1) * dt;
    const double speed = speeds[k], s = dists[k];
    const Eigen::Vector2d xy(xs[k], ys[k]);
    const double yaw = yaws[k];

    // Attitude from the ground under the tracks: a least-squares plane through 5 samples along each track, so
    // bumps shorter than the tracks are bridged as a real crawler does.
    const Eigen::Vector2d fwd(std::cos(yaw), std::sin(yaw)), left(-std::sin(yaw), std::cos(yaw));
    double mean = 0.0, side_diff = 0.0, slope_num = 0.0, slope_den = 0.0;
    double heights[2][5];
    for (int side = 0; side < 2; ++side) {
      for (int i = 0; i < 5; ++i) {
        const double f = c.track_length * (i - 2) / 4.0, l = (side == 0 ? 0.5 : -0.5) * c.track_width;
        const Eigen::Vector2d q = xy + f * fwd + l * left;
        heights[side][i] = world.groundHeight(q.x(), q.y());
        mean += heights[side][i] / 10.0;
        side_diff += (side == 0 ? 1.0 : -1.0) * heights[side][i] / 5.0;
      }
    }
    for (int side = 0; side < 2; ++side) {
      for (int i = 0; i < 5; ++i) {
        const double f = c.track_length * (i - 2) / 4.0;
        slope_num += f * (heights[side][i] - mean);
        slope_den += f * f;
      }
    }
    const double z_ground = mean;
    const double pitch_floor = -std::atan(slope_num / slope_den);      // nose up = negative pitch
    const double roll_floor = std::atan2(side_diff, c.track_width);  // left side up = positive roll

    const Eigen::Vector4d vib(vibration(0, t), vibration(1, t), vibration(2, t), vibration(3, t));
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
