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
  v[0] = std::min(std::max(0.0, c.start_speed), v[0]);
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
  c.start_speed = cfg.get(p + "start_speed", c.start_speed);
  c.stationary = cfg.get(p + "stationary", c.stationary);
  c.start_distance = cfg.get(p + "start_distance", c.start_distance);
  c.reverse = cfg.get(p + "reverse", c.reverse);
  c.mount_height = cfg.get(p + "mount_height", c.mount_height);
  c.track_length = cfg.get(p + "track_length", c.track_length);
  c.track_width = cfg.get(p + "track_width", c.track_width);
  c.vibration_deg = cfg.get(p + "vibration_deg", c.vibration_deg);
  c.bounce = cfg.get(p + "bounce", c.bounce);
  c.idle_vibration = cfg.get(p + "idle_vibration", c.idle_vibration);
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

namespace {

// Distance and speed along the path over time, from the speed profile (constant acceleration per grid cell).
class SpeedPlan {
 public:
  SpeedPlan(const Path2d& path, std::vector<double> v, double start_time)
      : length_(path.length()), v_(std::move(v)), start_(start_time) {
    n_ = static_cast<int>(v_.size()) - 1;
    ds_ = length_ / std::max(1, n_);
    t_grid_.assign(n_ + 1, 0.0);  // time to reach grid point i from the start of motion
    for (int i = 0; i < n_; ++i) t_grid_[i + 1] = t_grid_[i] + 2 * ds_ / std::max(1e-6, v_[i] + v_[i + 1]);
  }

  // Before the start the robot stands still, or, if it starts moving (v[0] > 0), it was driving at v[0]
  // (negative distance: behind the route's start).
  double distanceAt(double t, double& speed) const {
    t -= start_;
    if (t <= 0.0 || n_ <= 0) {
      speed = n_ > 0 ? v_[0] : 0.0;
      return speed > 0.0 ? speed * t : 0.0;
    }
    if (t >= t_grid_[n_]) {
      speed = v_[n_];
      return length_ + v_[n_] * (t - t_grid_[n_]);
    }
    const int i = static_cast<int>(std::upper_bound(t_grid_.begin(), t_grid_.end(), t) - t_grid_.begin()) - 1;
    const double a = (v_[i + 1] * v_[i + 1] - v_[i] * v_[i]) / (2 * ds_), tau = t - t_grid_[i];
    speed = v_[i] + a * tau;
    return std::min(i * ds_ + v_[i] * tau + 0.5 * a * tau * tau, (i + 1) * ds_);
  }

 private:
  double length_;
  std::vector<double> v_, t_grid_;
  double start_, ds_ = 0.0;
  int n_ = 0;
};

// Chassis vibration: per axis (pitch, roll, yaw, height) a sum of 3 sinusoids, unit RMS, amplitude ~ 1/f.
class Vibration {
 public:
  Vibration(Rng& rng, double f_min, double f_max) {
    const double lo = std::max(0.05, f_min), hi = std::max(lo, f_max);
    for (auto& axis : tones_) {
      double power = 0.0;
      for (Tone& tone : axis) {
        const double f = lo * std::pow(hi / lo, rng.uniform());
        tone = {2 * M_PI * f, rng.uniform(0.0, 2 * M_PI), 1.0 / f};
        power += 0.5 * tone.amplitude * tone.amplitude;
      }
      for (Tone& tone : axis) tone.amplitude /= std::sqrt(power);
    }
  }
  double value(int axis, double t) const {
    double sum = 0.0;
    for (const Tone& tone : tones_[axis]) sum += tone.amplitude * std::sin(tone.omega * t + tone.phase);
    return sum;
  }

 private:
  struct Tone {
    double omega, phase, amplitude;
  };
  std::array<std::array<Tone, 3>, 4> tones_{};
};

// Two passes of a centred moving average of half-width `half` samples (the window shrinks at the ends).
void smooth(std::vector<double>& series, int half) {
  const int n = static_cast<int>(series.size());
  for (int pass = 0; pass < 2 && half > 0; ++pass) {
    std::vector<double> prefix(n + 1, 0.0);
    for (int k = 0; k < n; ++k) prefix[k + 1] = prefix[k] + series[k];
    for (int k = 0; k < n; ++k) {
      const int w = std::min({half, k, n - 1 - k});
      series[k] = (prefix[k + w + 1] - prefix[k - w]) / (2 * w + 1);
    }
  }
}

struct GroundContact {
  double z, pitch, roll;  // ground height under the robot, and its attitude on the floor
};

// Least-squares plane through 5 floor samples along each track: bumps shorter than the tracks are bridged, as a
// real crawler does. Nose up = negative pitch, left side up = positive roll (z-y-x Euler angles).
GroundContact trackPlane(const World& world, const Eigen::Vector2d& xy, double yaw, const MotionConfig& c) {
  const Eigen::Vector2d fwd(std::cos(yaw), std::sin(yaw)), left(-std::sin(yaw), std::cos(yaw));
  double h[2][5], mean = 0.0, side_diff = 0.0;
  for (int side = 0; side < 2; ++side) {
    for (int i = 0; i < 5; ++i) {
      const Eigen::Vector2d q = xy + c.track_length * (i - 2) / 4.0 * fwd + (side == 0 ? 0.5 : -0.5) * c.track_width * left;
      h[side][i] = world.groundHeight(q.x(), q.y());
      mean += h[side][i] / 10.0;
      side_diff += (side == 0 ? 1.0 : -1.0) * h[side][i] / 5.0;
    }
  }
  double num = 0.0, den = 0.0;
  for (int side = 0; side < 2; ++side) {
    for (int i = 0; i < 5; ++i) {
      const double f = c.track_length * (i - 2) / 4.0;
      num += f * (h[side][i] - mean);
      den += f * f;
    }
  }
  return {mean, -std::atan(num / den), std::atan2(side_diff, c.track_width)};
}

}  // namespace

std::vector<Eigen::Vector2d> routeFrom(const std::vector<Eigen::Vector2d>& route, bool closed, double distance,
                                       bool reverse) {
  std::vector<Eigen::Vector2d> r(route);
  if (reverse) std::reverse(r.begin(), r.end());
  if (r.size() < 2 || !(distance > 0.0)) return r;
  double length = 0.0;
  for (std::size_t i = 1; i < r.size(); ++i) length += (r[i] - r[i - 1]).norm();
  if (closed && length > 0.0) distance = std::fmod(distance, length);
  // Segment i (r[i] -> r[i + 1]) holding the start, and the start point on it.
  std::size_t i = 0;
  double along = distance;
  while (i + 2 < r.size() && along > (r[i + 1] - r[i]).norm()) along -= (r[i + 1] - r[i]).norm(), ++i;
  const Eigen::Vector2d d = r[i + 1] - r[i];
  const Eigen::Vector2d start = r[i] + std::min(along, d.norm()) / std::max(1e-9, d.norm()) * d;
  std::vector<Eigen::Vector2d> out{start};
  out.insert(out.end(), r.begin() + static_cast<std::ptrdiff_t>(i + 1), r.end());
  if (closed) {
    out.insert(out.end(), r.begin() + 1, r.begin() + static_cast<std::ptrdiff_t>(i + 1));
    out.push_back(start);
  }
  // A start on a waypoint would repeat it (a zero-length segment).
  out.erase(std::unique(out.begin(), out.end(), [](const Eigen::Vector2d& a, const Eigen::Vector2d& b) {
              return (a - b).norm() < 1e-6;
            }), out.end());
  return out;
}

PlannedMotion planMotion(const World& world, const MotionConfig& c, double duration, std::uint64_t seed) {
  Rng rng = Rng::forStream(seed, Stream::Motion);
  const double horizon = std::max(0.0, duration) + 1.0;

  // Route: repeat closed routes until they cover the horizon at full speed.
  const std::vector<Eigen::Vector2d> route = routeFrom(world.route, world.route_closed, c.start_distance, c.reverse);
  std::vector<Eigen::Vector2d> waypoints = route;
  if (world.route_closed && route.size() > 2) {
    const double lap = std::max(1.0, world.routeLength());
    const int laps = 1 + static_cast<int>(std::ceil(horizon * c.max_speed / lap));
    for (int k = 1; k < laps; ++k) waypoints.insert(waypoints.end(), route.begin() + 1, route.end());
  }
  const Path2d path(waypoints, c.corner_radius);
  // The smoothing below reaches smoothing_window back in time: start moving that much later so the robot is
  // exactly still for start_still seconds. A robot already moving starts at once.
  // A stationary robot's motion starts after the horizon (the profile still draws its random numbers, so the
  // wander and vibration below are those of the same seed's drive).
  MotionConfig profile_config = c;
  if (c.stationary) profile_config.start_speed = 0.0;
  const bool moving_start = profile_config.start_speed > 0.0;
  const double start_time = c.stationary ? 2.0 * horizon + std::max(0.0, c.smoothing_window)
                            : moving_start ? 0.0
                                           : c.start_still + std::max(0.0, c.smoothing_window);
  const SpeedPlan plan(path, speedProfile(path, profile_config, !world.route_closed, rng), start_time);
  const double w1 = rng.uniform(20.0, 35.0), w2 = rng.uniform(45.0, 80.0);
  const double q1 = rng.uniform(0.0, 2 * M_PI), q2 = rng.uniform(0.0, 2 * M_PI);
  auto wander = [&](double s) {
    return c.wander * (0.6 * std::sin(2 * M_PI * s / w1 + q1) + 0.4 * std::sin(2 * M_PI * s / w2 + q2));
  };
  const Vibration vibration(rng, c.vibration_min_hz, c.vibration_max_hz);

  PlannedMotion out;
  out.route_length = path.length();
  out.lap_length = Path2d(route, c.corner_radius).length();
  const double dt = c.knot_spacing;
  const int controls = static_cast<int>(std::ceil(horizon / dt)) + 4;
  auto knotTime = [dt](int k) { return (k - 1) * dt; };  // control k belongs to time (k - 1) dt

  // Pass 1: planar pose along the path (with wander) at every knot; heading unwrapped.
  std::vector<double> xs(controls), ys(controls), yaws(controls), speeds(controls);
  out.knot_times.resize(controls);
  out.knot_distance.resize(controls);
  for (int k = 0; k < controls; ++k) {
    out.knot_times[k] = knotTime(k);
    out.knot_distance[k] = plan.distanceAt(knotTime(k), speeds[k]);
    const double s = std::min(out.knot_distance[k], path.length());
    Path2d::Sample ps = path.at(s);
    if (s < 0.0) ps.position += s * Eigen::Vector2d(std::cos(ps.heading), std::sin(ps.heading));  // behind the start
    const double offset = wander(s), slope = (wander(s + 0.05) - wander(s - 0.05)) / 0.1;
    xs[k] = ps.position.x() - offset * std::sin(ps.heading);
    ys[k] = ps.position.y() + offset * std::cos(ps.heading);
    yaws[k] = ps.heading + std::atan(slope);
    if (k > 0) yaws[k] = yaws[k - 1] + std::remainder(yaws[k] - yaws[k - 1], 2 * M_PI);
  }
  // Pass 2: a vehicle cannot jump in curvature or acceleration (the geometric path's arcs start abruptly).
  const int half_window = std::max(0, static_cast<int>(std::lround(0.5 * c.smoothing_window / dt)));
  for (std::vector<double>* series : {&xs, &ys, &yaws}) smooth(*series, half_window);

  // Pass 3: height and attitude from the floor, vibration scaled by speed, lidar on its mast.
  std::vector<Eigen::Isometry3d> poses(controls, Eigen::Isometry3d::Identity());
  for (int k = 0; k < controls; ++k) {
    const double t = knotTime(k);
    const GroundContact ground = trackPlane(world, {xs[k], ys[k]}, yaws[k], c);
    const double scale = std::max(c.idle_vibration, std::min(1.5, speeds[k] / 1.0));
    const double sigma = c.vibration_deg * kDegToRad * scale;
    const Eigen::Matrix3d R =
        (Eigen::AngleAxisd(yaws[k] + sigma / 3 * vibration.value(2, t), Eigen::Vector3d::UnitZ()) *
         Eigen::AngleAxisd(ground.pitch + sigma * vibration.value(0, t), Eigen::Vector3d::UnitY()) *
         Eigen::AngleAxisd(ground.roll + sigma * vibration.value(1, t), Eigen::Vector3d::UnitX()))
            .toRotationMatrix();
    poses[k].linear() = R;
    poses[k].translation() = Eigen::Vector3d(xs[k], ys[k], ground.z + c.bounce * scale * vibration.value(3, t)) +
                             R * Eigen::Vector3d(0.0, 0.0, c.mount_height);
  }
  out.trajectory = BSplineTrajectory(0.0, dt, std::move(poses));
  return out;
}

}  // namespace adit::sim
