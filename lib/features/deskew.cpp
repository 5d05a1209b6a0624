#include "features/deskew.hpp"

#include "core/geometry.hpp"

#include <algorithm>
#include <cmath>

namespace adit::features {
namespace {

// Orientation of the IMU at absolute time t (s) relative to the first sample, by integrating the gyro.
struct GyroIntegrator {
  std::vector<double> t;                 // sample times (s)
  std::vector<Eigen::Vector3d> rate;     // mean rate over [t_k, t_k+1] (last: the last sample's rate)
  std::vector<Eigen::Quaterniond> q;     // orientation at t_k

  explicit GyroIntegrator(std::vector<ImuSample> s) {
    std::stable_sort(s.begin(), s.end(), [](const ImuSample& a, const ImuSample& b) { return a.utime < b.utime; });
    for (std::size_t k = 0; k < s.size(); ++k) {
      t.push_back(toSeconds(s[k].utime));
      rate.push_back(k + 1 < s.size() ? 0.5 * (s[k].gyro + s[k + 1].gyro) : s[k].gyro);
    }
    q.push_back(Eigen::Quaterniond::Identity());
    for (std::size_t k = 0; k + 1 < t.size(); ++k)
      q.push_back((q[k] * Eigen::Quaterniond(expRotation(rate[k] * (t[k + 1] - t[k])))).normalized());
  }

  Eigen::Quaterniond at(double time) const {
    const std::size_t k = static_cast<std::size_t>(
        std::max<std::ptrdiff_t>(0, std::upper_bound(t.begin(), t.end(), time) - t.begin() - 1));
    const Eigen::Vector3d& w = (time < t[k]) ? rate.front() : rate[k];  // before the first sample: extrapolate
    return (q[k] * Eigen::Quaterniond(expRotation(w * (time - t[k])))).normalized();
  }
};

// ((1 - f) R0 + f R1) p + (1 - f) t0 + f t1, written out: the same operations in the same order as Eigen's
// expression (a row times p sums as a0 + (a1 + a2)), so the result is bit-identical, without Eigen building
// the blended 3x3 matrix in a temporary for every point.
Eigen::Vector3f blendedPose(const Eigen::Matrix3f& R0, const Eigen::Matrix3f& R1, const Eigen::Vector3f& t0,
                            const Eigen::Vector3f& t1, float f, const Eigen::Vector3f& p) {
  const float g = 1.0f - f;
  Eigen::Vector3f out;
  for (int i = 0; i < 3; ++i) {
    const float m0 = g * R0(i, 0) + f * R1(i, 0), m1 = g * R0(i, 1) + f * R1(i, 1), m2 = g * R0(i, 2) + f * R1(i, 2);
    out[i] = (m0 * p[0] + (m1 * p[1] + m2 * p[2]) + g * t0[i]) + f * t1[i];
  }
  return out;
}

bool priorUsable(const MotionPrior& m, const DeskewConfig& cfg) {
  return m.valid && m.dt_s > 1e-3 && m.dt_s <= cfg.max_prior_dt_s && m.T_prev_curr.matrix().allFinite();
}

}  // namespace

Eigen::Isometry3d motionModelPose(const MotionPrior& motion, double dt) {
  return interpolate(Eigen::Isometry3d::Identity(), motion.T_prev_curr.inverse(), -dt / motion.dt_s);
}

std::vector<Eigen::Quaterniond> imuRotations(const std::vector<ImuSample>& imu, std::int64_t end_utime,
                                             const std::vector<double>& times, const Eigen::Quaterniond& R_lidar_imu,
                                             double max_gap_s) {
  if (imu.empty() || times.empty()) return {};
  for (const ImuSample& s : imu)
    if (!s.gyro.allFinite()) return {};
  const GyroIntegrator gyro(imu);
  const double end = toSeconds(end_utime), start = end + times.front();
  if (gyro.t.front() > start + max_gap_s || gyro.t.back() < end - max_gap_s) return {};
  const Eigen::Quaterniond q_end_inv = gyro.at(end).conjugate();
  std::vector<Eigen::Quaterniond> out;
  out.reserve(times.size());
  for (double dt : times) {
    const Eigen::Quaterniond q_imu = q_end_inv * gyro.at(end + dt);  // IMU at dt, in IMU frame at the end
    out.push_back((R_lidar_imu * q_imu * R_lidar_imu.conjugate()).normalized());
  }
  return out;
}

std::int32_t deskewPoints(std::vector<LidarPoint>& points, std::int64_t utime, float sweep_duration,
                          const std::vector<ImuSample>& imu, const MotionPrior& motion, const DeskewConfig& cfg) {
  if (!cfg.enabled || points.empty()) return 0;
  const double sweep = std::max<double>(sweep_duration, 1e-3);
  const int steps = std::max(1, cfg.table_steps);
  std::vector<double> times(steps + 1);
  for (int k = 0; k <= steps; ++k) times[k] = -sweep + sweep * k / steps;

  const bool use_motion = priorUsable(motion, cfg);
  const std::vector<Eigen::Quaterniond> imu_q = imuRotations(imu, utime, times, cfg.R_lidar_imu, cfg.max_imu_gap_s);
  if (imu_q.empty() && !use_motion) return 0;
  if (!use_motion && !cfg.rotation_only_without_prior) return 0;

  std::vector<Eigen::Matrix3f> R(steps + 1);
  std::vector<Eigen::Vector3f> t(steps + 1, Eigen::Vector3f::Zero());
  for (int k = 0; k <= steps; ++k) {
    const Eigen::Isometry3d T = use_motion ? motionModelPose(motion, times[k]) : Eigen::Isometry3d::Identity();
    R[k] = (imu_q.empty() ? T.linear() : imu_q[k].toRotationMatrix()).cast<float>();
    t[k] = T.translation().cast<float>();
  }
  // Linear interpolation between table poses 3 ms apart: the rotation matrices differ by ~1e-3 rad, so the
  // blend stays orthonormal to ~1e-6.
  for (LidarPoint& p : points) {
    const double u = std::clamp((p.dt + sweep) / sweep, 0.0, 1.0) * steps;
    const int k = std::min(static_cast<int>(u), steps - 1);
    p.p = blendedPose(R[k], R[k + 1], t[k], t[k + 1], static_cast<float>(u - k), p.p);
  }
  return (imu_q.empty() ? 0 : FeatureSet::kDeskewImu) | (use_motion ? FeatureSet::kDeskewMotion : 0);
}

}  // namespace adit::features
