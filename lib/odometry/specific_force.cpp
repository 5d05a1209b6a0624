#include "odometry/specific_force.hpp"

namespace adit {

SpecificForceIntegral integrateSpecificForce(const std::vector<ImuSample>& imu, std::int64_t since,
                                             std::int64_t utime, const Eigen::Matrix3d& R_curr_prev,
                                             const Eigen::Quaterniond& R_lidar_imu, double max_gap_s) {
  SpecificForceIntegral out;
  if (since < 0 || utime <= since || !R_curr_prev.allFinite()) return out;
  const Eigen::Quaterniond q_prev(R_curr_prev), identity = Eigen::Quaterniond::Identity();
  const Eigen::Quaterniond R_li = R_lidar_imu.normalized();
  const std::int64_t max_gap = toUtime(max_gap_s);
  const double span = static_cast<double>(utime - since);
  std::int64_t t = since;
  Eigen::Vector3d force = Eigen::Vector3d::Zero();
  const auto integrate = [&out](const Eigen::Vector3d& f, double dt) {
    out.displacement += out.velocity_change * dt + 0.5 * f * dt * dt;
    out.velocity_change += f * dt;
  };
  for (const ImuSample& m : imu) {
    if (m.utime <= since) continue;
    if (m.utime > utime) break;
    if (m.utime - t > max_gap || !m.accel.allFinite()) return SpecificForceIntegral{};
    const Eigen::Quaterniond q = q_prev.slerp(static_cast<double>(m.utime - since) / span, identity);
    force = q * (R_li * m.accel);
    integrate(force, toSeconds(m.utime - t));
    t = m.utime;
  }
  if (t == since || utime - t > max_gap) return SpecificForceIntegral{};
  integrate(force, toSeconds(utime - t));  // the last sample's force holds to the interval's end
  out.since_utime = since;
  return out;
}

}  // namespace adit
