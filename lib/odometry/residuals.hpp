// Ceres cost functors over the local increment xi = (rho, phi) of pose_increment.hpp.
//
// Lines and planes are given in the linearisation frame T0 (the caller moves them there once per outer
// iteration), so a source point p maps to q = exp(phi) p + rho and residuals are plain point-line/plane
// distances in metres. No intra-sweep interpolation: the FeatureSet is already deskewed to its utime.
#pragma once

#include <ceres/rotation.h>

#include <Eigen/Core>

namespace adit {

template <class T>
inline void transformByIncrement(const T* xi, const Eigen::Vector3d& p, T q[3]) {
  const T p_t[3] = {T(p.x()), T(p.y()), T(p.z())};
  ceres::AngleAxisRotatePoint(xi + 3, p_t, q);
  for (int i = 0; i < 3; ++i) q[i] += xi[i];
}

// Component of (q - a) orthogonal to the line direction u: 3 residuals, rank 2. Smooth at zero, unlike the
// scalar distance, which keeps Gauss-Newton well behaved when a point already lies on its line.
struct PointToLineResidual {
  Eigen::Vector3d p, a, u;
  template <class T>
  bool operator()(const T* xi, T* r) const {
    T q[3];
    transformByIncrement(xi, p, q);
    const T d[3] = {q[0] - T(a.x()), q[1] - T(a.y()), q[2] - T(a.z())};
    const T along = d[0] * T(u.x()) + d[1] * T(u.y()) + d[2] * T(u.z());
    for (int i = 0; i < 3; ++i) r[i] = d[i] - along * T(u[i]);
    return true;
  }
};

// Signed distance of q to the plane n . x + c = 0.
struct PointToPlaneResidual {
  Eigen::Vector3d p, n;
  double c = 0.0;
  template <class T>
  bool operator()(const T* xi, T* r) const {
    T q[3];
    transformByIncrement(xi, p, q);
    r[0] = T(n.x()) * q[0] + T(n.y()) * q[1] + T(n.z()) * q[2] + T(c);
    return true;
  }
};

// Prior on one tangent direction only: weight * v . (xi - target). Holds a degenerate direction to the
// motion model while leaving the well-observed directions to the measurements.
struct DirectionalPriorResidual {
  Eigen::Matrix<double, 6, 1> v, target;
  double weight = 1.0;
  template <class T>
  bool operator()(const T* xi, T* r) const {
    T sum(0.0);
    for (int i = 0; i < 6; ++i) sum += T(v[i]) * (xi[i] - T(target[i]));
    r[0] = T(weight) * sum;
    return true;
  }
};

}  // namespace adit
