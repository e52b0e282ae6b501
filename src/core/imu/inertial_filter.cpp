#include "elo/imu/inertial_filter.hpp"

#include <Eigen/Cholesky>
#include <Eigen/Geometry>

namespace elo {

namespace {

// The registered translation's error (m per scan, each axis): a registration's noise on the swung
// VLP-16's instantaneous scans, against which the accelerometers carry the velocity; the deskewed sweeps'
// registrations are better, and the filter then trusts the IMU more than it need.
constexpr double kRegisteredTranslationSigma = 0.02;
// m/s per root second: how far the velocity carried by the accelerometers may stray (their noise, the
// gyro's error turning gravity into them, the interpolation between samples).
constexpr double kVelocityWalk = 0.1;
// m/s^2 per root second: gravity in the world frame moves only with the odometry's own attitude drift.
constexpr double kGravityWalk = 0.01;
constexpr double kBiasPrior = 0.1;               // m/s^2: a consumer MEMS unit's bias is 5 mg = 0.05 m/s^2
constexpr double kInitialVelocitySigma = 3.0;    // m/s: unknown, a walk or a car starting
constexpr double kInitialGravitySigma = 1.5;     // m/s^2: the first interval's mean acceleration

Eigen::Vector3d vectorOf(const std::vector<double>& values) { return {values[0], values[1], values[2]}; }

}  // namespace

InertialFilter::InertialFilter(const ImuConfig& config)
    : bias_walk_(config.accel_bias_time_constant > 0.0 ? kBiasPrior * kBiasPrior / config.accel_bias_time_constant
                                                        : 0.0),
      gate_margin_(config.accel_gate) {
  setMount(config);
}

void InertialFilter::setMount(const ImuConfig& config) {
  lever_ = config.position.size() == 3 ? vectorOf(config.position) : Eigen::Vector3d::Zero();
  lidar_from_imu_ = config.rotation_deg.size() == 3 ? lidarFromImuRotation(config) : Eigen::Matrix3d::Identity();
  reset();
}

Eigen::Vector3d InertialFilter::predictTranslation(const Preintegration& motion, const Eigen::Matrix3d& attitude,
                                                   const Eigen::Matrix3d& rotation) const {
  const double dt = motion.duration;
  const Eigen::Vector3d u = state_.head<3>();
  const Eigen::Vector3d g = state_.segment<3>(3);
  const Eigen::Vector3d b = state_.tail<3>();
  return attitude.transpose() * (u * dt + 0.5 * g * dt * dt) + motion.position - motion.position_by_bias * b -
         (rotation * lever_ - lever_);
}

void InertialFilter::start(const Preintegration& motion, const Eigen::Matrix3d& attitude) {
  state_.setZero();
  // The mean specific force over the interval, in the world: gravity less the mean acceleration, which the
  // registrations that follow tell apart.
  state_.segment<3>(3) = -attitude * motion.velocity / motion.duration;
  covariance_.setZero();
  covariance_.block<3, 3>(0, 0).diagonal().setConstant(kInitialVelocitySigma * kInitialVelocitySigma);
  covariance_.block<3, 3>(3, 3).diagonal().setConstant(kInitialGravitySigma * kInitialGravitySigma);
  covariance_.block<3, 3>(6, 6).diagonal().setConstant(bias_walk_ > 0.0 ? kBiasPrior * kBiasPrior : 0.0);
  started_ = true;
  velocity_updates_ = 0;
}

bool InertialFilter::update(const Preintegration& motion, const Eigen::Matrix3d& attitude,
                            const Eigen::Isometry3d& registered, const std::optional<Eigen::Vector3d>& lidar_prior) {
  if (!(motion.duration > 0.0)) return true;
  if (!started_) start(motion, attitude);
  const double dt = motion.duration;
  // The registered translation as a measurement of R^T u dt + R^T g dt^2 / 2 - J_p b.
  const Eigen::Vector3d measured =
      registered.translation() + (registered.linear() * lever_ - lever_) - motion.position;
  Eigen::Matrix<double, 3, 9> h;
  h << attitude.transpose() * dt, 0.5 * dt * dt * attitude.transpose(), -motion.position_by_bias;
  const Eigen::Vector3d innovation = measured - h * state_;
  if (disagrees(innovation, registered, lidar_prior)) {
    // The interval's force misled the velocity it carries on: gravity and the bias are carried over the
    // interval, the velocity is measured again from the registrations that follow.
    propagate(motion, attitude);
    forgetVelocity();
    return false;
  }
  const Eigen::Matrix3d s =
      h * covariance_ * h.transpose() + Eigen::Matrix3d::Identity() * kRegisteredTranslationSigma * kRegisteredTranslationSigma;
  const Eigen::Matrix<double, 9, 3> gain = covariance_ * h.transpose() * s.inverse();
  state_ += gain * innovation;
  const Matrix9d keep = Matrix9d::Identity() - gain * h;
  covariance_ = keep * covariance_ * keep.transpose() +
                gain * gain.transpose() * kRegisteredTranslationSigma * kRegisteredTranslationSigma;
  ++velocity_updates_;
  propagate(motion, attitude);
  return true;
}

bool InertialFilter::disagrees(const Eigen::Vector3d& innovation, const Eigen::Isometry3d& registered,
                               const std::optional<Eigen::Vector3d>& lidar_prior) const {
  // Without a velocity from a registration before, the innovation is the velocity's, not the force's.
  if (velocity_updates_ == 0 || !lidar_prior) return false;
  return innovation.norm() > (registered.translation() - *lidar_prior).norm() + gate_margin_;
}

void InertialFilter::propagate(const Preintegration& motion, const Eigen::Matrix3d& attitude) {
  if (!started_ || !(motion.duration > 0.0)) return;
  const double dt = motion.duration;
  Matrix9d f = Matrix9d::Identity();
  f.block<3, 3>(0, 3) = Eigen::Matrix3d::Identity() * dt;
  f.block<3, 3>(0, 6) = -attitude * motion.velocity_by_bias;
  state_ = f * state_;
  state_.head<3>() += attitude * motion.velocity;
  covariance_ = f * covariance_ * f.transpose();
  covariance_.block<3, 3>(0, 0).diagonal().array() += kVelocityWalk * kVelocityWalk * dt;
  covariance_.block<3, 3>(3, 3).diagonal().array() += kGravityWalk * kGravityWalk * dt;
  covariance_.block<3, 3>(6, 6).diagonal().array() += bias_walk_ * dt;
}

void InertialFilter::forgetVelocity() {
  state_.head<3>().setZero();
  covariance_.block<3, 9>(0, 0).setZero();
  covariance_.block<9, 3>(0, 0).setZero();
  covariance_.block<3, 3>(0, 0).diagonal().setConstant(kInitialVelocitySigma * kInitialVelocitySigma);
  velocity_updates_ = 0;
}

void InertialFilter::reset() {
  started_ = false;
  velocity_updates_ = 0;
  state_.setZero();
  covariance_.setZero();
}

void InertialFilter::turnWorld(const Eigen::Matrix3d& rotation) {
  Matrix9d turn = Matrix9d::Identity();
  turn.block<3, 3>(0, 0) = rotation;
  turn.block<3, 3>(3, 3) = rotation;
  state_ = turn * state_;
  covariance_ = turn * covariance_ * turn.transpose();
}

Eigen::Vector3d InertialFilter::worldForce(const Preintegration& motion, const Eigen::Matrix3d& attitude) const {
  return attitude * (motion.velocity - motion.velocity_by_bias * state_.tail<3>());
}

Eigen::Vector3d InertialFilter::learntBias() const { return lidar_from_imu_.transpose() * state_.tail<3>(); }

}  // namespace elo
