// SE(3) exponential and logarithm for the Gauss-Newton update T <- exp(delta) * T (Sec. III-A).
// A twist is (rho, phi): translation part first, rotation part second, matching the Jacobian
// n^T [I, -[p]x] of the point-to-plane residual.
#pragma once

#include <Eigen/Geometry>

namespace elo {

using Vector6d = Eigen::Matrix<double, 6, 1>;
using Matrix6d = Eigen::Matrix<double, 6, 6>;

Eigen::Matrix3d skew(const Eigen::Vector3d& v);
Eigen::Isometry3d expSE3(const Vector6d& twist);
Vector6d logSE3(const Eigen::Isometry3d& transform);
// The rotation vector (axis times angle, rad) of a rotation: what a rate integrates to, and back.
Eigen::Vector3d logSO3(const Eigen::Matrix3d& rotation);

// Rotation angle (rad) of a transform.
double rotationAngle(const Eigen::Isometry3d& transform);

}  // namespace elo
