// Robot motion: drives the world's route like a crawler/wheeled mine robot and returns the lidar's ground-truth
// trajectory as a smooth B-spline.
//
// Model (all from the seed):
//  - speed profile along the route: cruise speed with slow +-variation, slowed to the lateral-acceleration limit
//    in corners (turns at junctions), accelerations limited to max_accel / max_decel, starting from rest after
//    a still period (lets IMU-based pipelines initialise gravity and biases) and stopping at the route's end;
//    or, with start_speed > 0, already driving at that speed at time 0 (a log cut from the middle of a drive);
//  - a slow lateral wander around the centre line (nobody drives a perfect line);
//  - the planar motion is smoothed (moving average, twice, over smoothing_window) so curvature and acceleration
//    change continuously, as a real vehicle's do;
//  - height, pitch and roll from a plane fitted to the floor under the two tracks (so pitch/roll really come from
//    the rugged floor; bumps shorter than the tracks are bridged), plus chassis vibration in pitch, roll, yaw and height: per axis a sum of 3 sinusoids with
//    seeded frequencies in [vibration_min_hz, vibration_max_hz] (amplitude ~ 1/f), scaled by speed (never below
//    idle_vibration: an idling engine), so it is band-limited like a real chassis and its accelerations stay physical;
//  - or, with stationary, no motion at all: the robot stands at the route's start for the whole run;
//  - the lidar sits mount_height above the ground on the body z axis; the IMU is at the lidar (identity extrinsic).
// The resulting poses are sampled every knot_spacing seconds and become the control points of the spline; the
// spline IS the ground truth (its derivatives feed the IMU).
#pragma once

#include "core/config.hpp"
#include "sim/bspline_trajectory.hpp"
#include "sim/world.hpp"

#include <cstdint>
#include <vector>

namespace adit::sim {

struct MotionConfig {
  double cruise_speed = 1.3;     // m/s; mine robots drive 0.5-1.5 m/s
  double speed_variation = 0.1;  // relative slow variation of the cruise speed (+-)
  double max_speed = 1.5;        // m/s hard cap
  double max_accel = 0.3;        // m/s^2 (a crawler on a rough floor)
  double max_decel = 0.5;        // m/s^2
  double lateral_accel = 0.3;    // m/s^2 in corners -> ~0.77 m/s through a 2 m radius turn
  double corner_radius = 2.0;    // m, fits a 4.5 m wide junction
  double wander = 0.15;          // m, amplitude of the lateral wander around the centre line
  double start_still = 2.0;      // s standing still at the start (ignored when start_speed > 0)
  double start_speed = 0.0;      // m/s already driven at time 0 (capped by the speed limits there); 0 = from rest
  // The robot never moves: it stands at its start pose for the whole run (start_still and start_speed ignored):
  // for measuring what the estimate does at rest (issue 16).
  bool stationary = false;
  // Where on the route the drive starts (m along it; closed routes wrap round, open ones drop what lies before)
  // and in which direction: a later drive through a mapped roadway that starts somewhere else (issue 18).
  double start_distance = 0.0;
  bool reverse = false;  // drive the route backwards
  double mount_height = 1.0;     // m, lidar above the ground contact
  double track_length = 1.2;     // m, length of the tracks on the ground (pitch from the floor)
  double track_width = 0.8;      // m, distance between the tracks (roll from the floor)
  double vibration_deg = 0.3;    // deg RMS pitch/roll vibration at 1 m/s (yaw gets a third of it)
  double bounce = 0.004;         // m RMS vertical vibration at 1 m/s
  // Vibration while standing (engine idling), as a fraction of the vibration at 1 m/s; 0 = none at rest.
  double idle_vibration = 0.0;
  double vibration_min_hz = 0.8; // chassis vibration band (Hz)
  double vibration_max_hz = 4.0;
  double knot_spacing = 0.02;    // s between spline control points (>= 12 knots per vibration period)
  double smoothing_window = 0.6; // s, moving average (twice) over the planar path: smooth curvature and jerk
};

// Keys "sim.motion.<field>" with the defaults above.
MotionConfig motionConfigFrom(const adit::Config& c);

struct PlannedMotion {
  BSplineTrajectory trajectory;  // T_world_lidar, valid on [0, duration + 1 s]
  // Distance along the route driven by time knot_times[k] (monotonic): for "how long to drive X metres".
  std::vector<double> knot_times, knot_distance;
  double route_length = 0.0;  // total length of the (possibly repeated) route that was planned (m)
  double lap_length = 0.0;    // length of one pass of world.route as driven (corners rounded) (m)
  double timeAtDistance(double metres) const;  // first time the robot has driven `metres`; +inf if never
};

// The route a drive follows: reversed when asked, then starting `distance` metres along it (closed routes
// wrap round to their start, open ones drop what lies before; a closed route's last waypoint equals its first).
std::vector<Eigen::Vector2d> routeFrom(const std::vector<Eigen::Vector2d>& route, bool closed, double distance,
                                       bool reverse);

// Plans `duration` seconds (+1 s margin) of motion along world.route. Closed routes are repeated lap after lap.
PlannedMotion planMotion(const World& world, const MotionConfig& config, double duration, std::uint64_t seed);

}  // namespace adit::sim
