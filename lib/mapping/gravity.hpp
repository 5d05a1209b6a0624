// The map's "down", and the levelling that turns the map back to it.
//
// Registration against the map pins a sweep's pitch and roll to the map's, but nothing pins the map's: sweeps
// enter it at their registered poses, so a tilt error of a few thousandths of a degree a sweep accumulates and
// bends a long map (measured in a featureless kilometre: -0.6 deg of pitch after 800 s, 4 m of height at its
// end, with an exact IMU as well as a noisy one). An accelerometer measures the specific force
// f = R^T (a - g) (+9.81 up at rest), and the odometry hands it on preintegrated between sweeps
// (odometry/specific_force.hpp).
//
// GravityObserver finds gravity in the map frame from the mapper's own poses: with S(t) the specific force
// rotated into the map by the registered rotations and integrated twice from the window's first sweep, the
// registered positions obey p(t) = p0 + v0 t + g t^2 / 2 + S(t), so a quadratic fitted by least squares to
// p - S over window_s gives g (the linear alignment of visual-inertial initialisation, with lidar positions).
// Whatever the robot's acceleration does inside the window S carries exactly. Only the window's relative
// rotations enter: the odometry's would not do, as they follow a gyro whose bias walks away from what its
// last stop measured (the featureless kilometre: 0.5-0.8 deg of roll and pitch error over 10 s late in the
// run, and a gravity 0.6 deg off), while the mapper's are held by the map. Measured against the truth
// (10 s window): 0.03 deg with an exact IMU; with the simulated N100, its accelerometer's bias (3 mg: ~0.2 deg).
//
// GravityReference: the map's down is the mean of the first reference_sweeps gravities found. From then on,
// every window_s, the local map and the sweep just registered turn together about the sweep's position, about
// the horizontal axis that takes the gravity found onto the map's down, by window_s / time_constant_s of the
// angle between them: a correction of fixed gain, so the map's tilt error decays over time_constant_s whatever
// the lidar observes, and the window the gravity is found over turns with the map, so the next window sees
// what is left. Turning the sweep alone does little: the next registration pulls it back to the tilt the map
// holds (the featureless kilometre: pitch -0.53 instead of -0.57 deg after 800 s with a 60 s time constant).
// A prior weighed inside the registration takes the gain the lidar leaves it: little in pitch, pinned by the
// floor, and all of the roll in a round tube, where the window's delay made it oscillate and diverge (roll
// +-2 deg after 15 s, 73 deg after 25 s with a prior of 0.03 deg). Heading is left alone.
// The accelerometer's bias b adds the same vector to every measurement in the body frame, R b in the map's, and
// the reference, measured at the rotation R0, holds R0 b: while the heading stays near the start's it cancels,
// but a turn shows it as (R - R0) b, up to twice bias / 9.81 (~0.35 deg for 3 mg), which levelling alone
// turned into the map (issue 16's 700 s loop: APE 0.0488 -> 0.0575 m). So b is estimated too, by least squares
// of the gravities found against g0 + (R - R0) b with a prior of bias_sigma_mps2, and taken out before
// levelling: observable only where the heading changes, which is where it matters. What is left of it still
// tilts a structured map a little after turns, hence a slow time_constant_s: with 240 s the 700 s loop's APE is
// 0.0470 m and its map as near the world as unlevelled, and the kilometre's height error 1.1 m (4.1 m
// unlevelled); with 120 s 0.19 m, but that loop's map 16 % further from the world (docs/measurements.md, "Gravity").
#pragma once

#include "core/config_table.hpp"
#include "core/types.hpp"

#include <deque>
#include <optional>

namespace adit {

struct GravityConfig {
  double window_s = 10.0;          // span of the sweeps gravity is fitted over; 0: gravity is not found
  double tolerance_mps2 = 1.0;     // |g| further than this from 9.80665 m/s^2: the fit is not trusted
  double time_constant_s = 240.0;  // a tilt error decays over this; 0: the tilt is not corrected
  int reference_sweeps = 20;       // gravities averaged into the map's down before the map is levelled to it
  double bias_sigma_mps2 = 0.05;   // prior of the accelerometer's bias (the N100: ~0.03 m/s^2 per axis)
  double fit_sigma_mps2 = 0.2;     // weight of one gravity found (consecutive windows share most sweeps)
  // A tilt larger than this is not the map's drift (hundredths of a degree a minute) but an accelerometer that
  // is mounted otherwise than configured, or failing: no turn, counted gravity_disagrees.
  double max_tilt_rad = 0.035;     // 2 deg
};

// Keys "<prefix>.*" ("mapping.gravity").
ConfigTable<GravityConfig> gravityConfigTable(const std::string& prefix);

class GravityObserver {
 public:
  explicit GravityObserver(GravityConfig config = {}) : config_(config) {}

  // The sweep at utime (in time order), registered at T_world_lidar, with the accelerometer since the sweep
  // before (lidar frame at utime). Returns gravity in the world frame (m/s^2, pointing down) once a window of
  // sweeps joined by integrals spans window_s; a sweep without one starts the window again.
  std::optional<Eigen::Vector3d> add(std::int64_t utime, const Eigen::Isometry3d& T_world_lidar,
                                     const SpecificForceIntegral& force);
  void reset() { sweeps_.clear(); }
  // A loop closure moved the trajectory: the window moves with it.
  void applyCorrection(const Eigen::Isometry3d& T_corrected_uncorrected);
  // Fits whose |g| was outside the tolerance (a badly scaled or failing accelerometer).
  int rejected() const { return rejected_; }

 private:
  struct Sweep {
    std::int64_t utime = 0;
    Eigen::Vector3d position = Eigen::Vector3d::Zero();
    Eigen::Vector3d velocity_change = Eigen::Vector3d::Zero();  // world frame, since the sweep before
    Eigen::Vector3d displacement = Eigen::Vector3d::Zero();
  };
  Eigen::Vector3d fit() const;

  GravityConfig config_;
  std::deque<Sweep> sweeps_;
  int rejected_ = 0;
};

class GravityReference {
 public:
  explicit GravityReference(GravityConfig config = {}) : config_(config) {}

  // The turn that takes the local map window_s / time_constant_s of the way from the gravity found (world frame,
  // the accelerometer's bias taken out for the sweep's rotation) to the map's down, about the sweep's position,
  // when window_s has passed since the last one at utime; none before the map's down is known, without a
  // gravity, with time_constant_s 0, or for a tilt beyond max_tilt_rad (counted).
  std::optional<Eigen::Isometry3d> levelling(const std::optional<Eigen::Vector3d>& gravity_world,
                                             const Eigen::Isometry3d& T_world_lidar, std::int64_t utime);
  // A gravity found (world frame) over the sweeps up to one registered at T_world_lidar: the first
  // reference_sweeps set the map's down, the later ones the accelerometer's bias.
  void observe(const Eigen::Vector3d& gravity_world, const Eigen::Isometry3d& T_world_lidar);
  // The accelerometer's bias as estimated so far (body frame, m/s^2).
  Eigen::Vector3d bias() const;
  // Levellings refused because the tilt exceeded max_tilt_rad.
  int disagreements() const { return disagreements_; }
  bool known() const { return count_ >= config_.reference_sweeps && down_sum_.norm() > 0.0; }

  // What a restarted mapper keeps: the sum of the unit gravities (world frame) and their number.
  struct State {
    Eigen::Vector3d down_sum = Eigen::Vector3d::Zero();
    int count = 0;
    Eigen::Matrix3d R_reference = Eigen::Matrix3d::Identity();
  };
  State state() const { return {down_sum_, count_, R_reference_}; }
  void restore(const State& s);

 private:
  GravityConfig config_;
  Eigen::Vector3d down() const;  // the map's down, m/s^2
  Eigen::Vector3d down_sum_ = Eigen::Vector3d::Zero();
  int count_ = 0;
  Eigen::Matrix3d R_reference_ = Eigen::Matrix3d::Identity();  // rotation of the sweep the reference began at
  Eigen::Matrix3d bias_normal_ = Eigen::Matrix3d::Zero();      // bias least squares, without the prior
  Eigen::Vector3d bias_rhs_ = Eigen::Vector3d::Zero();
  std::int64_t last_levelling_ = -1;
  int disagreements_ = 0;
};

}  // namespace adit
