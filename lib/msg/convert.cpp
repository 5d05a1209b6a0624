#include "msg/convert.hpp"

#include "core/geometry.hpp"
#include "msg/sweep_header.hpp"

#include <algorithm>
#include <cmath>

namespace adit::msg {
namespace {

void copyMatrix6(const Matrix6d& m, double out[36]) {
  for (int r = 0; r < 6; ++r)
    for (int c = 0; c < 6; ++c) out[r * 6 + c] = m(r, c);
}

Matrix6d readMatrix6(const double in[36]) {
  Matrix6d m;
  for (int r = 0; r < 6; ++r)
    for (int c = 0; c < 6; ++c) m(r, c) = in[r * 6 + c];
  return m;
}

}  // namespace

adit::header_t makeHeader(std::int64_t utime, const std::string& frame_id) {
  adit::header_t h;
  h.utime = utime;
  h.seq = 0;
  h.frame_id = frame_id;
  return h;
}

adit::point_cloud_t toMessage(const std::vector<LidarPoint>& points, const LidarScan& like) {
  adit::point_cloud_t m;
  m.header = makeHeader(like.utime, "lidar");
  m.header.seq = like.seq;
  m.sensor = like.sensor;
  m.num_beams = static_cast<std::int16_t>(like.num_beams);
  m.sweep_duration = like.sweep_duration;
  m.flags = sweepFlags(like);
  const std::size_t n = points.size();
  m.num_points = static_cast<std::int32_t>(n);
  m.x.resize(n);
  m.y.resize(n);
  m.z.resize(n);
  m.intensity.resize(n);
  m.ring.resize(n);
  m.dt.resize(n);
  for (std::size_t i = 0; i < n; ++i) {
    const LidarPoint& p = points[i];
    m.x[i] = p.p.x();
    m.y[i] = p.p.y();
    m.z[i] = p.p.z();
    m.intensity[i] = p.intensity;
    m.ring[i] = static_cast<std::int16_t>(p.ring);
    m.dt[i] = p.dt;
  }
  return m;
}

adit::point_cloud_t toMessage(const LidarScan& scan) { return toMessage(scan.points, scan); }

std::vector<LidarPoint> pointsFromMessage(const adit::point_cloud_t& m) {
  // LCM guarantees every array has num_points entries once decoded.
  const auto n = static_cast<std::size_t>(std::max(0, m.num_points));
  std::vector<LidarPoint> points(n);
  for (std::size_t i = 0; i < n; ++i) {
    LidarPoint& p = points[i];
    p.p = Eigen::Vector3f(m.x[i], m.y[i], m.z[i]);
    p.intensity = m.intensity[i];
    p.ring = static_cast<std::uint16_t>(std::max<std::int16_t>(0, m.ring[i]));
    p.dt = m.dt[i];
  }
  return points;
}

LidarScan fromMessage(const adit::point_cloud_t& m) {
  LidarScan scan = sweepHeader(m);
  scan.points = pointsFromMessage(m);
  return scan;
}

adit::imu_t toMessage(const ImuSample& imu) {
  adit::imu_t m;
  m.header = makeHeader(imu.utime, "imu");
  for (int i = 0; i < 3; ++i) {
    m.angular_velocity[i] = imu.gyro[i];
    m.linear_acceleration[i] = imu.accel[i];
    m.magnetic_field[i] = imu.magnetic_field ? (*imu.magnetic_field)[i] : 0.0;
  }
  const Eigen::Quaterniond q = imu.orientation.value_or(Eigen::Quaterniond::Identity());
  m.orientation[0] = q.w();
  m.orientation[1] = q.x();
  m.orientation[2] = q.y();
  m.orientation[3] = q.z();
  m.has_magnetometer = imu.magnetic_field.has_value();
  m.has_orientation = imu.orientation.has_value();
  return m;
}

ImuSample fromMessage(const adit::imu_t& m) {
  ImuSample imu;
  imu.utime = m.header.utime;
  imu.gyro = Eigen::Vector3d(m.angular_velocity[0], m.angular_velocity[1], m.angular_velocity[2]);
  imu.accel = Eigen::Vector3d(m.linear_acceleration[0], m.linear_acceleration[1], m.linear_acceleration[2]);
  if (m.has_magnetometer)
    imu.magnetic_field = Eigen::Vector3d(m.magnetic_field[0], m.magnetic_field[1], m.magnetic_field[2]);
  if (m.has_orientation)
    imu.orientation = Eigen::Quaterniond(m.orientation[0], m.orientation[1], m.orientation[2], m.orientation[3]).normalized();
  return imu;
}

adit::wheel_odom_t toMessage(const WheelOdomSample& w) {
  adit::wheel_odom_t m;
  m.header = makeHeader(w.utime, "base");
  m.speed = w.speed;
  m.yaw_rate = w.yaw_rate;
  m.speed_sigma = w.speed_sigma;
  m.yaw_rate_sigma = w.yaw_rate_sigma;
  return m;
}

WheelOdomSample fromMessage(const adit::wheel_odom_t& m) {
  return {m.header.utime, m.speed, m.yaw_rate, m.speed_sigma, m.yaw_rate_sigma};
}

adit::features_t toMessage(const FeatureSet& f) {
  adit::features_t m;
  m.header = makeHeader(f.utime, "lidar");
  m.header.seq = f.cloud.seq;
  m.sensor = f.cloud.sensor;
  m.num_beams = static_cast<std::int16_t>(f.cloud.num_beams);
  m.sweep_duration = f.cloud.sweep_duration;
  m.sweep_flags = sweepFlags(f.cloud);
  // Times only for a raw sweep: registration compensates it with them; a deskewed one needs none.
  // One grid for the LOAM sets: the odometry matches flat / sharp points against the less-flat / less-sharp
  // sets that contain them.
  const float loam_scale = std::max({pointSetScale(f.corner_sharp), pointSetScale(f.corner_less_sharp),
                                     pointSetScale(f.surf_flat), pointSetScale(f.surf_less_flat)});
  const PointSetFields loam{true, !f.cloud.deskewed, loam_scale};
  m.corner_sharp = toPointSet(f.corner_sharp, loam);
  m.corner_less_sharp = toPointSet(f.corner_less_sharp, loam);
  m.surf_flat = toPointSet(f.surf_flat, loam);
  m.surf_less_flat = toPointSet(f.surf_less_flat, loam);
  m.map_cloud = toPointSet(f.cloud.points, {false, !f.cloud.deskewed});
  const std::size_t n = std::min(f.keypoints.size(), f.descriptors.size());
  m.num_keypoints = static_cast<std::int32_t>(n);
  m.descriptor_size = static_cast<std::int16_t>(kLinK3dBins);
  m.descriptor_scale = kDescriptorScale;
  m.keypoints.assign(n, std::vector<float>(3));
  m.descriptors.assign(n, std::vector<std::int16_t>(kLinK3dBins));
  for (std::size_t i = 0; i < n; ++i) {
    for (int k = 0; k < 3; ++k) m.keypoints[i][k] = f.keypoints[i][k];
    for (int b = 0; b < kLinK3dBins; ++b) {
      const float d = f.descriptors[i][static_cast<std::size_t>(b)];
      // A non-empty bin never rounds to the empty value 0.
      const long c = d > 0.0f ? std::max(1L, std::lround(d / kDescriptorScale)) : 0L;
      m.descriptors[i][static_cast<std::size_t>(b)] = static_cast<std::int16_t>(std::min(c, 32767L));
    }
  }
  m.flags = f.flags;
  m.points_in = f.points_in;
  m.removed_invalid = f.removed_invalid;
  m.removed_range = f.removed_range;
  m.removed_outlier = f.removed_outlier;
  return m;
}

void keypointsOf(const adit::features_t& m, std::vector<Eigen::Vector3f>& keypoints,
                 std::vector<LinK3dDescriptor>& descriptors) {
  keypoints.clear();
  descriptors.clear();
  // A descriptor of another size cannot be compared with ours: keep the keypoints only if sizes agree.
  if (m.descriptor_size != kLinK3dBins || !(m.descriptor_scale > 0.0f) || !std::isfinite(m.descriptor_scale)) return;
  for (int i = 0; i < m.num_keypoints; ++i) {
    keypoints.emplace_back(m.keypoints[i][0], m.keypoints[i][1], m.keypoints[i][2]);
    LinK3dDescriptor d{};
    for (int b = 0; b < kLinK3dBins; ++b)
      d[static_cast<std::size_t>(b)] = static_cast<float>(m.descriptors[i][static_cast<std::size_t>(b)]) * m.descriptor_scale;
    descriptors.push_back(d);
  }
}

FeatureSet fromMessage(const adit::features_t& m) {
  FeatureSet f;
  f.utime = m.header.utime;
  f.cloud.utime = m.header.utime;
  f.cloud.seq = m.header.seq;
  f.cloud.sensor = m.sensor;
  f.cloud.num_beams = m.num_beams;
  f.cloud.sweep_duration = m.sweep_duration;
  setSweepFlags(m.sweep_flags, f.cloud);
  f.cloud.points = fromPointSet(m.map_cloud);
  f.corner_sharp = fromPointSet(m.corner_sharp);
  f.corner_less_sharp = fromPointSet(m.corner_less_sharp);
  f.surf_flat = fromPointSet(m.surf_flat);
  f.surf_less_flat = fromPointSet(m.surf_less_flat);
  keypointsOf(m, f.keypoints, f.descriptors);
  f.flags = m.flags;
  f.points_in = m.points_in;
  f.removed_invalid = m.removed_invalid;
  f.removed_range = m.removed_range;
  f.removed_outlier = m.removed_outlier;
  return f;
}

adit::odometry_t toMessage(const PoseEstimate& pose, const FeatureSet* features) {
  adit::odometry_t m;
  m.header = makeHeader(pose.utime, "world");
  splitPose(pose.pose, m.position, m.orientation);
  copyMatrix6(pose.covariance, m.covariance);
  for (int i = 0; i < 3; ++i) {
    m.translation_eigenvalues[i] = pose.translation_eigenvalues[i];
    m.rotation_eigenvalues[i] = pose.rotation_eigenvalues[i];
  }
  m.flags = pose.flags;
  const double identity_position[3] = {0, 0, 0}, identity_rotation[4] = {1, 0, 0, 0};
  std::copy(identity_position, identity_position + 3, m.loop_correction_position);
  std::copy(identity_rotation, identity_rotation + 4, m.loop_correction_orientation);
  m.imu_since_utime = pose.specific_force.since_utime;
  for (int i = 0; i < 3; ++i) {
    m.imu_velocity_change[i] = pose.specific_force.velocity_change[i];
    m.imu_displacement[i] = pose.specific_force.displacement[i];
    m.gravity[i] = pose.gravity[i];
  }
  m.iterations = pose.iterations;
  m.final_cost = pose.final_cost;
  m.sweep_flags = 0;
  m.corners = m.surfaces = m.cloud = emptyPointSet();
  if (features) {
    m.sweep_flags = sweepFlags(features->cloud);
    const bool times = !features->cloud.deskewed;
    m.corners = toPointSet(features->corner_less_sharp, {false, times});
    m.surfaces = toPointSet(features->surf_less_flat, {false, times});
    m.cloud = toPointSet(features->cloud.points, {false, times});
  }
  return m;
}

FeatureSet featuresOf(const adit::odometry_t& m) {
  FeatureSet f;
  f.utime = m.header.utime;
  f.cloud.utime = m.header.utime;
  setSweepFlags(m.sweep_flags, f.cloud);
  f.corner_less_sharp = fromPointSet(m.corners);
  f.surf_less_flat = fromPointSet(m.surfaces);
  f.cloud.points = fromPointSet(m.cloud);
  return f;
}

void stripPoints(adit::odometry_t& m) { m.corners = m.surfaces = m.cloud = emptyPointSet(); }

PoseEstimate fromMessage(const adit::odometry_t& m) {
  PoseEstimate p;
  p.utime = m.header.utime;
  p.pose = makePose(m.position, m.orientation);
  p.covariance = readMatrix6(m.covariance);
  for (int i = 0; i < 3; ++i) {
    p.translation_eigenvalues[i] = m.translation_eigenvalues[i];
    p.rotation_eigenvalues[i] = m.rotation_eigenvalues[i];
  }
  p.flags = m.flags;
  // validate() refuses a non-finite IMU part on the bus; a caller without it still gets none, never a NaN.
  const Eigen::Vector3d gravity(m.gravity[0], m.gravity[1], m.gravity[2]);
  if (gravity.allFinite()) p.gravity = gravity;
  const Eigen::Vector3d dv(m.imu_velocity_change[0], m.imu_velocity_change[1], m.imu_velocity_change[2]);
  const Eigen::Vector3d dp(m.imu_displacement[0], m.imu_displacement[1], m.imu_displacement[2]);
  if (m.imu_since_utime >= 0 && m.imu_since_utime < m.header.utime && dv.allFinite() && dp.allFinite())
    p.specific_force = {m.imu_since_utime, dv, dp};  // otherwise none
  p.iterations = m.iterations;
  p.final_cost = m.final_cost;
  return p;
}

adit::loop_closure_t toMessage(const LoopConstraint& loop, std::int64_t utime) {
  adit::loop_closure_t m;
  m.header = makeHeader(utime, "world");
  m.query_index = loop.query_index;
  m.match_index = loop.match_index;
  m.query_utime = loop.query_utime;
  m.match_utime = loop.match_utime;
  splitPose(loop.T_match_query, m.relative_position, m.relative_orientation);
  copyMatrix6(loop.information, m.information);
  m.scan_context_distance = loop.scan_context_distance;
  m.scan_context_yaw = loop.scan_context_yaw;
  m.fitness = loop.fitness;
  m.inlier_ratio = loop.inlier_ratio;
  return m;
}

LoopConstraint fromMessage(const adit::loop_closure_t& m) {
  LoopConstraint l;
  l.query_index = m.query_index;
  l.match_index = m.match_index;
  l.query_utime = m.query_utime;
  l.match_utime = m.match_utime;
  l.T_match_query = makePose(m.relative_position, m.relative_orientation);
  l.information = readMatrix6(m.information);
  l.scan_context_distance = m.scan_context_distance;
  l.scan_context_yaw = m.scan_context_yaw;
  l.fitness = m.fitness;
  l.inlier_ratio = m.inlier_ratio;
  return l;
}

}  // namespace adit::msg
