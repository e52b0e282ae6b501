#include "elo/se3.hpp"

#include <cmath>

namespace elo {

namespace {
// Below this rotation angle the series expansions replace the closed forms, whose terms cancel.
constexpr double kSmallAngle = 1e-6;
}

Eigen::Matrix3d skew(const Eigen::Vector3d& v) {
  Eigen::Matrix3d m;
  m << 0.0, -v.z(), v.y(), v.z(), 0.0, -v.x(), -v.y(), v.x(), 0.0;
  return m;
}

Eigen::Isometry3d expSE3(const Vector6d& twist) {
  const Eigen::Vector3d rho = twist.head<3>();
  const Eigen::Vector3d phi = twist.tail<3>();
  const double angle = phi.norm();
  const Eigen::Matrix3d K = skew(phi);
  Eigen::Matrix3d V;
  Eigen::Matrix3d R;
  if (angle < kSmallAngle) {
    R = Eigen::Matrix3d::Identity() + K + 0.5 * K * K;
    V = Eigen::Matrix3d::Identity() + 0.5 * K + K * K / 6.0;
  } else {
    const double a2 = angle * angle;
    R = Eigen::AngleAxisd(angle, phi / angle).toRotationMatrix();
    V = Eigen::Matrix3d::Identity() + (1.0 - std::cos(angle)) / a2 * K + (angle - std::sin(angle)) / (a2 * angle) * K * K;
  }
  Eigen::Isometry3d transform = Eigen::Isometry3d::Identity();
  transform.linear() = R;
  transform.translation() = V * rho;
  return transform;
}

Eigen::Vector3d logSO3(const Eigen::Matrix3d& rotation) {
  const Eigen::AngleAxisd angle_axis(rotation);
  return angle_axis.angle() * angle_axis.axis();
}

Vector6d logSE3(const Eigen::Isometry3d& transform) {
  const Eigen::AngleAxisd angle_axis(transform.linear());
  const double angle = angle_axis.angle();
  const Eigen::Vector3d phi = angle * angle_axis.axis();
  const Eigen::Matrix3d K = skew(phi);
  Eigen::Matrix3d V_inverse;
  if (angle < kSmallAngle) {
    V_inverse = Eigen::Matrix3d::Identity() - 0.5 * K + K * K / 12.0;
  } else {
    const double a2 = angle * angle;
    V_inverse = Eigen::Matrix3d::Identity() - 0.5 * K +
                (1.0 - angle * std::sin(angle) / (2.0 * (1.0 - std::cos(angle)))) / a2 * K * K;
  }
  Vector6d twist;
  twist.head<3>() = V_inverse * transform.translation();
  twist.tail<3>() = phi;
  return twist;
}

// Through the quaternion: acos of the trace loses precision for the small angles convergence tests see.
double rotationAngle(const Eigen::Isometry3d& transform) {
  return Eigen::AngleAxisd(transform.linear()).angle();
}

}  // namespace elo
