// Value checks of decoded messages, one per message type, run by the node on every input before the stage
// sees it (runtime/node.hpp): a stage never receives a NaN pose, a gyro reading of 1e30 rad/s or a string of
// megabytes. A message that fails is counted under the returned counter and dropped.
//
// Non-finite points of a raw sweep (point_cloud_t on its own) are NOT refused here: preprocessing removes
// and counts them (features_t.removed_invalid). Derived point sets (features, odometry) must be finite.
#pragma once

#include <adit/command_t.hpp>
#include <adit/features_t.hpp>
#include <adit/imu_t.hpp>
#include <adit/loop_closure_t.hpp>
#include <adit/odometry_t.hpp>
#include <adit/odometry_v1_t.hpp>
#include <adit/point_cloud_t.hpp>
#include <adit/point_set_t.hpp>
#include <adit/pose_graph_t.hpp>
#include <adit/status_t.hpp>
#include <adit/wheel_odom_t.hpp>

#include <optional>
#include <string>

namespace adit::msg {

// Physical and sanity limits (defaults suit the supported sensors: a 2000 deg/s, 16 g MEMS IMU).
struct InputLimits {
  double max_angular_velocity = 40.0;    // rad/s (2000 deg/s = 34.9 rad/s full scale)
  double max_acceleration = 200.0;       // m/s^2 (16 g full scale = 157 m/s^2)
  double max_wheel_speed = 50.0;         // m/s of wheel odometry (a road vehicle's 180 km/h)
  double max_magnetic_field = 1e-3;      // tesla (the Earth's field is ~5e-5)
  double quaternion_tolerance = 1e-3;    // allowed | |q| - 1 |
  double max_position = 1e6;             // metres from the origin
  double max_sweep_duration = 10.0;      // seconds
  std::size_t max_string_length = 4096;  // bytes, for text fields (command arguments, frame ids)
};

// Why a message was refused: the counter it goes to and a line saying what was wrong.
struct Invalid {
  std::string counter;  // "invalid_nonfinite", "invalid_range", "invalid_quaternion", "invalid_count", "invalid_string"
  std::string reason;
};
using Validation = std::optional<Invalid>;  // empty: the message is usable

Validation validate(const adit::header_t& m, const InputLimits& limits);
Validation validate(const adit::imu_t& m, const InputLimits& limits);
Validation validate(const adit::wheel_odom_t& m, const InputLimits& limits);
Validation validate(const adit::point_cloud_t& m, const InputLimits& limits);
Validation validate(const adit::features_t& m, const InputLimits& limits);
Validation validate(const adit::odometry_t& m, const InputLimits& limits);
Validation validate(const adit::odometry_v1_t& m, const InputLimits& limits);  // older logs
Validation validate(const adit::loop_closure_t& m, const InputLimits& limits);
Validation validate(const adit::pose_graph_t& m, const InputLimits& limits);
Validation validate(const adit::command_t& m, const InputLimits& limits);
Validation validate(const adit::status_t& m, const InputLimits& limits);

}  // namespace adit::msg
