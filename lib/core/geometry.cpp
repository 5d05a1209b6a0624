#include "core/geometry.hpp"

#include <cmath>

namespace adit {

Eigen::Isometry3d interpolate(const Eigen::Isometry3d& a, const Eigen::Isometry3d& b, double s) {
  const Eigen::Quaterniond qa(a.linear()), qb(b.linear());
  Eigen::Isometry3d out = Eigen::Isometry3d::Identity();
  out.linear() = qa.slerp(s, qb).normalized().toRotationMatrix();
  out.translation() = (1.0 - s) * a.translation() + s * b.translation();
  return out;
}

Eigen::Vector3d logRotation(const Eigen::Matrix3d& R) {
  const Eigen::AngleAxisd aa(R);
  return aa.angle() * aa.axis();
}

Eigen::Matrix3d expRotation(const Eigen::Vector3d& w) {
  const double angle = w.norm();
  if (angle < 1e-12) return Eigen::Matrix3d::Identity();
  return Eigen::AngleAxisd(angle, w / angle).toRotationMatrix();
}

Eigen::Isometry3d makePose(const double position[3], const double wxyz[4]) {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  Eigen::Quaterniond q(wxyz[0], wxyz[1], wxyz[2], wxyz[3]);
  if (q.norm() < 1e-9) q = Eigen::Quaterniond::Identity();
  T.linear() = q.normalized().toRotationMatrix();
  T.translation() = Eigen::Vector3d(position[0], position[1], position[2]);
  return T;
}

void splitPose(const Eigen::Isometry3d& T, double position[3], double wxyz[4]) {
  const Eigen::Quaterniond q(T.linear());
  for (int i = 0; i < 3; ++i) position[i] = T.translation()[i];
  wxyz[0] = q.w();
  wxyz[1] = q.x();
  wxyz[2] = q.y();
  wxyz[3] = q.z();
}

double rotationAngle(const Eigen::Isometry3d& T) { return Eigen::AngleAxisd(T.linear()).angle(); }
double translationNorm(const Eigen::Isometry3d& T) { return T.translation().norm(); }

}  // namespace adit
