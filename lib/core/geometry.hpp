// Small pose helpers shared by stages (pure functions over Eigen types).
#pragma once

#include "core/types.hpp"

namespace adit {

// Interpolate between two poses: translation linearly, rotation by slerp; s in [0, 1].
Eigen::Isometry3d interpolate(const Eigen::Isometry3d& a, const Eigen::Isometry3d& b, double s);

// Rotation vector (axis * angle) of a rotation, and back.
Eigen::Vector3d logRotation(const Eigen::Matrix3d& R);
Eigen::Matrix3d expRotation(const Eigen::Vector3d& w);

// Isometry from position + quaternion given as w, x, y, z (message order), and back.
Eigen::Isometry3d makePose(const double position[3], const double wxyz[4]);
void splitPose(const Eigen::Isometry3d& T, double position[3], double wxyz[4]);

// Rotation angle of T in radians and translation norm in metres.
double rotationAngle(const Eigen::Isometry3d& T);
double translationNorm(const Eigen::Isometry3d& T);

}  // namespace adit
