#include "msg/validate.hpp"

#include <cmath>
#include <vector>

namespace adit::msg {
namespace {

// Collects the first failure; each check names the field it looked at.
class Check {
 public:
  explicit Check(const InputLimits& limits) : limits_(limits) {}

  template <class T>
  Check& finite(const char* field, const T* values, std::size_t n) {
    for (std::size_t i = 0; i < n && !failed(); ++i)
      if (!std::isfinite(values[i])) fail("invalid_nonfinite", std::string(field) + " is not finite");
    return *this;
  }
  template <class T>
  Check& finite(const char* field, const std::vector<T>& values) {
    return finite(field, values.data(), values.size());
  }
  Check& finite(const char* field, double value) { return finite(field, &value, 1); }

  // |v| of a 3-vector (after it was found finite) within a physical limit.
  Check& norm3(const char* field, const double* v, double limit) {
    if (!failed() && std::sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]) > limit)
      fail("invalid_range", std::string(field) + " magnitude exceeds " + std::to_string(limit));
    return *this;
  }
  // A scalar (after it was found finite) within [lo, hi].
  Check& within(const char* field, double v, double lo, double hi) {
    if (!failed() && (v < lo || v > hi))
      fail("invalid_range", std::string(field) + " = " + std::to_string(v) + " is outside [" + std::to_string(lo) +
                                ", " + std::to_string(hi) + "]");
    return *this;
  }
  Check& position(const char* field, const double* p) {
    finite(field, p, 3);
    return norm3(field, p, limits_.max_position);
  }
  Check& quaternion(const char* field, const double* q) {
    finite(field, q, 4);
    const double norm = std::sqrt(q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3]);
    if (!failed() && std::abs(norm - 1.0) > limits_.quaternion_tolerance)
      fail("invalid_quaternion", std::string(field) + " has norm " + std::to_string(norm) + ", not 1");
    return *this;
  }
  Check& count(const char* field, bool consistent) {
    if (!failed() && !consistent) fail("invalid_count", std::string(field) + " does not match its arrays");
    return *this;
  }
  Check& text(const char* field, const std::string& s) {
    if (!failed() && s.size() > limits_.max_string_length)
      fail("invalid_string", std::string(field) + " is " + std::to_string(s.size()) + " bytes long (limit " +
                                 std::to_string(limits_.max_string_length) + ")");
    return *this;
  }
  Check& merge(const Validation& inner) {
    if (!failed() && inner) result_ = inner;
    return *this;
  }

  const InputLimits& limits() const { return limits_; }
  Validation result() const { return result_; }

 private:
  bool failed() const { return result_.has_value(); }
  void fail(const char* counter, std::string reason) { result_ = Invalid{counter, std::move(reason)}; }

  const InputLimits& limits_;
  Validation result_;
};

// A point set: counts match the arrays, time and duration sane; `points_finite` for derived sets.
Validation cloud(const adit::point_cloud_t& m, const InputLimits& limits, bool points_finite) {
  const auto n = static_cast<std::size_t>(m.num_points);
  Check c(limits);
  c.merge(validate(m.header, limits)).text("sensor", m.sensor);
  c.count("num_points", m.num_points >= 0 && m.x.size() == n && m.y.size() == n && m.z.size() == n &&
                            m.intensity.size() == n && m.ring.size() == n && m.dt.size() == n);
  c.count("num_beams", m.num_beams >= 0);
  c.finite("sweep_duration", static_cast<double>(m.sweep_duration));
  if (m.sweep_duration < 0 || m.sweep_duration > limits.max_sweep_duration)
    c.count("sweep_duration", false);
  if (points_finite) c.finite("x", m.x).finite("y", m.y).finite("z", m.z).finite("dt", m.dt);
  return c.result();
}

// A compact point set (point_set_t): a positive finite scale, counts that match the arrays, rings and times
// either absent or one per point, finite times. int16 coordinates cannot be non-finite.
Validation pointSet(const adit::point_set_t& m, const InputLimits& limits) {
  const auto n = static_cast<std::size_t>(m.num_points);
  Check c(limits);
  c.finite("scale", static_cast<double>(m.scale));
  c.count("scale", m.scale > 0);
  c.count("num_points", m.num_points >= 0 && m.x.size() == n && m.y.size() == n && m.z.size() == n);
  c.count("num_rings", (m.num_rings == 0 || m.num_rings == m.num_points) &&
                           m.ring.size() == static_cast<std::size_t>(std::max(0, m.num_rings)));
  c.count("num_times", (m.num_times == 0 || m.num_times == m.num_points) &&
                           m.dt.size() == static_cast<std::size_t>(std::max(0, m.num_times)));
  c.finite("dt", m.dt);
  return c.result();
}

}  // namespace

Validation validate(const adit::header_t& m, const InputLimits& limits) {
  return Check(limits).text("header.frame_id", m.frame_id).result();
}

Validation validate(const adit::imu_t& m, const InputLimits& limits) {
  Check c(limits);
  c.merge(validate(m.header, limits));
  c.finite("angular_velocity", m.angular_velocity, 3).norm3("angular_velocity", m.angular_velocity,
                                                            limits.max_angular_velocity);
  c.finite("linear_acceleration", m.linear_acceleration, 3)
      .norm3("linear_acceleration", m.linear_acceleration, limits.max_acceleration);
  if (m.has_magnetometer)
    c.finite("magnetic_field", m.magnetic_field, 3).norm3("magnetic_field", m.magnetic_field, limits.max_magnetic_field);
  if (m.has_orientation) c.quaternion("orientation", m.orientation);
  return c.result();
}

Validation validate(const adit::wheel_odom_t& m, const InputLimits& limits) {
  Check c(limits);
  c.merge(validate(m.header, limits));
  c.finite("speed", m.speed).within("speed", m.speed, -limits.max_wheel_speed, limits.max_wheel_speed);
  c.finite("yaw_rate", m.yaw_rate)
      .within("yaw_rate", m.yaw_rate, -limits.max_angular_velocity, limits.max_angular_velocity);
  c.finite("speed_sigma", m.speed_sigma).within("speed_sigma", m.speed_sigma, 0.0, limits.max_wheel_speed);
  c.finite("yaw_rate_sigma", m.yaw_rate_sigma)
      .within("yaw_rate_sigma", m.yaw_rate_sigma, 0.0, limits.max_angular_velocity);
  return c.result();
}

Validation validate(const adit::point_cloud_t& m, const InputLimits& limits) { return cloud(m, limits, false); }

Validation validate(const adit::features_t& m, const InputLimits& limits) {
  Check c(limits);
  c.merge(validate(m.header, limits)).text("sensor", m.sensor);
  c.count("num_beams", m.num_beams >= 0);
  c.finite("sweep_duration", static_cast<double>(m.sweep_duration));
  if (m.sweep_duration < 0 || m.sweep_duration > limits.max_sweep_duration) c.count("sweep_duration", false);
  for (const adit::point_set_t* set : {&m.corner_sharp, &m.corner_less_sharp, &m.surf_flat, &m.surf_less_flat, &m.map_cloud})
    c.merge(pointSet(*set, limits));
  const auto k = static_cast<std::size_t>(m.num_keypoints);
  bool rows = m.num_keypoints >= 0 && m.descriptor_size >= 0 && m.keypoints.size() == k && m.descriptors.size() == k;
  for (std::size_t i = 0; rows && i < k; ++i)
    rows = m.keypoints[i].size() == 3 && m.descriptors[i].size() == static_cast<std::size_t>(m.descriptor_size);
  c.count("num_keypoints", rows);
  c.finite("descriptor_scale", static_cast<double>(m.descriptor_scale));
  for (std::size_t i = 0; rows && i < k; ++i) c.finite("keypoints", m.keypoints[i]);
  return c.result();
}

namespace {
// odometry_t and its older layout share these fields.
template <class Odometry>
Validation validateOdometry(const Odometry& m, const InputLimits& limits) {
  Check c(limits);
  c.merge(validate(m.header, limits)).position("position", m.position).quaternion("orientation", m.orientation);
  c.finite("covariance", m.covariance, 36)
      .finite("translation_eigenvalues", m.translation_eigenvalues, 3)
      .finite("rotation_eigenvalues", m.rotation_eigenvalues, 3);
  c.position("loop_correction_position", m.loop_correction_position)
      .quaternion("loop_correction_orientation", m.loop_correction_orientation)
      .finite("final_cost", m.final_cost);
  for (const adit::point_set_t* set : {&m.corners, &m.surfaces, &m.cloud}) c.merge(pointSet(*set, limits));
  return c.result();
}
}  // namespace

// The accelerometer's preintegration and gravity are optional, but "none" is imu_since_utime -1 and a zero
// gravity, never a NaN or a start after the sweep: such fields come from a broken producer, and the message is
// refused as any other non-finite field would have it.
Validation validate(const adit::odometry_t& m, const InputLimits& limits) {
  Check c(limits);
  c.merge(validateOdometry(m, limits));
  c.finite("imu_velocity_change", m.imu_velocity_change, 3)
      .finite("imu_displacement", m.imu_displacement, 3)
      .finite("gravity", m.gravity, 3)
      .norm3("gravity", m.gravity, limits.max_acceleration);
  if (m.imu_since_utime != -1)
    c.within("imu_since_utime", static_cast<double>(m.imu_since_utime), 0.0, static_cast<double>(m.header.utime) - 1.0);
  return c.result();
}
Validation validate(const adit::odometry_v1_t& m, const InputLimits& limits) { return validateOdometry(m, limits); }

Validation validate(const adit::loop_closure_t& m, const InputLimits& limits) {
  Check c(limits);
  c.merge(validate(m.header, limits))
      .position("relative_position", m.relative_position)
      .quaternion("relative_orientation", m.relative_orientation)
      .finite("information", m.information, 36);
  c.finite("scan_context_distance", m.scan_context_distance)
      .finite("scan_context_yaw", m.scan_context_yaw)
      .finite("fitness", m.fitness)
      .finite("inlier_ratio", m.inlier_ratio);
  c.count("query_index", m.query_index >= 0 && m.match_index >= 0);
  return c.result();
}

Validation validate(const adit::pose_graph_t& m, const InputLimits& limits) {
  Check c(limits);
  c.merge(validate(m.header, limits));
  const auto n = static_cast<std::size_t>(m.num_nodes);
  bool rows = m.num_nodes >= 0 && m.node_utime.size() == n && m.position.size() == n && m.orientation.size() == n;
  for (std::size_t i = 0; rows && i < n; ++i) rows = m.position[i].size() == 3 && m.orientation[i].size() == 4;
  c.count("num_nodes", rows);
  for (std::size_t i = 0; rows && i < n; ++i)
    c.position("position", m.position[i].data()).quaternion("orientation", m.orientation[i].data());
  c.position("correction_position", m.correction_position)
      .quaternion("correction_orientation", m.correction_orientation);
  c.count("num_loops", m.num_loops >= 0);
  // The newest loop is meaningful only once there is one.
  if (m.num_loops > 0) c.merge(validate(m.newest_loop, limits));
  return c.result();
}

Validation validate(const adit::command_t& m, const InputLimits& limits) {
  Check c(limits);
  c.merge(validate(m.header, limits)).text("command", m.command).text("argument", m.argument);
  // A signature is an HMAC-SHA256 (32 bytes) or absent; any other size is not one.
  c.count("mac_size", (m.mac_size == 0 || m.mac_size == 32) && m.mac.size() == static_cast<std::size_t>(m.mac_size));
  return c.result();
}

Validation validate(const adit::status_t& m, const InputLimits& limits) {
  Check c(limits);
  c.merge(validate(m.header, limits)).text("process", m.process).text("state", m.state).text("last_error", m.last_error);
  c.count("num_counters", m.num_counters >= 0 && m.counter_names.size() == static_cast<std::size_t>(m.num_counters) &&
                              m.counter_values.size() == static_cast<std::size_t>(m.num_counters));
  return c.result();
}

}  // namespace adit::msg
