// What the accelerometers say of the motion (docs/imu.md): the IMU's velocity, gravity and the
// accelerometers' bias, estimated against the LiDAR's registered translations by a linear Kalman filter
// (loosely coupled: the registration is the measurement, the integrated specific force the process),
// and from them the translation of the next scan's motion prior.
//
// The state, at the reference instant of the scan registered last: the IMU's velocity u and gravity g
// (m/s, m/s^2, in the odometry's world frame, the first scan's, which need not be level) and the
// accelerometers' bias b (m/s^2, the LiDAR's axes). Over an interval of dt seconds starting with the
// LiDAR at attitude R, with the IMU's motion P, V (Preintegration) and the IMU at r in the LiDAR frame,
//   the LiDAR's translation, in its frame at the start:  R^T u dt + R^T g dt^2 / 2 + P - J_p b - (dR r - r)
//   the IMU's velocity at the end:                        u + g dt + R (V - J_v b)
// Both are linear in the state; the lever arm's terms (w' x r, w x (w x r)) are in the IMU's own point
// moving by dR r - r. An interval whose force predicted the registered translation worse than the
// LiDAR-only prior did is gated (update(), imu.accel_gate): aliased samples would mislead the velocity.
#pragma once

#include <Eigen/Core>
#include <optional>

#include "elo/config.hpp"
#include "elo/imu/imu_track.hpp"

namespace elo {

class InertialFilter {
 public:
  explicit InertialFilter(const ImuConfig& config);
  // The mount (imu.position, imu.rotation_deg) known once running (the node's, from TF): what the filter
  // holds is forgotten, its bias being in the axes of the mount it had.
  void setMount(const ImuConfig& config);

  // Whether gravity has been taken (the filter started), and the velocity known from two registrations
  // in a row: one alone may be a start search's wrong motion, which the next is refused against.
  bool started() const { return started_; }
  bool ready() const { return started_ && velocity_updates_ >= kUpdatesForVelocity; }
  // The LiDAR's translation over `motion` in its frame at the start, `attitude` its rotation in the world
  // there, turning by `rotation` over it (the gyro's). Meaningful when ready().
  Eigen::Vector3d predictTranslation(const Preintegration& motion, const Eigen::Matrix3d& attitude,
                                     const Eigen::Matrix3d& rotation) const;
  // The LiDAR registered `registered` over `motion` (starting at `attitude`): the state is corrected by
  // its translation, then carried to the interval's end. The first call starts the filter: gravity is
  // taken as the mean specific force over the interval, loosely (the sensor may be accelerating).
  // The gate (imu.accel_gate): once a registration gave the velocity, an interval whose predicted
  // translation misses `registered` by more than `lidar_prior` (the LiDAR-only prior's translation, when
  // there was one) did, plus the margin, is not taken: its force is taken to mislead (an aliased sample),
  // the velocity is forgotten and the filter is not ready() again until two registrations gave it. False
  // when the interval was gated.
  bool update(const Preintegration& motion, const Eigen::Matrix3d& attitude, const Eigen::Isometry3d& registered,
              const std::optional<Eigen::Vector3d>& lidar_prior = std::nullopt);
  // Carries the state over `motion` without a registration.
  void propagate(const Preintegration& motion, const Eigen::Matrix3d& attitude);
  // The velocity becomes unknown (the IMU could not cover an interval); gravity and the bias stay.
  void forgetVelocity();
  // Everything is forgotten: the world frame changes.
  void reset();

  // The world frame turned by `rotation` (a correction of the odometry's attitude, TiltHold): the
  // velocity and gravity, which the filter holds in it, are turned alike.
  void turnWorld(const Eigen::Matrix3d& rotation);

  // The specific force integrated over `motion` (m/s), less the bias learnt, in the world frame: the
  // change of the IMU's velocity less gravity's, `attitude` the LiDAR's rotation in the world at its start.
  Eigen::Vector3d worldForce(const Preintegration& motion, const Eigen::Matrix3d& attitude) const;

  Eigen::Vector3d gravity() const { return state_.segment<3>(3); }
  Eigen::Vector3d velocity() const { return state_.head<3>(); }
  // The bias estimated online (m/s^2, the IMU's axes), on top of imu.accel_bias.
  Eigen::Vector3d learntBias() const;

 private:
  using Vector9d = Eigen::Matrix<double, 9, 1>;
  using Matrix9d = Eigen::Matrix<double, 9, 9>;
  void start(const Preintegration& motion, const Eigen::Matrix3d& attitude);
  // Whether the interval's innovation (the registered translation less the predicted one) is gated.
  bool disagrees(const Eigen::Vector3d& innovation, const Eigen::Isometry3d& registered,
                 const std::optional<Eigen::Vector3d>& lidar_prior) const;

  Eigen::Vector3d lever_;            // the IMU's origin in the LiDAR frame, m
  Eigen::Matrix3d lidar_from_imu_;
  double bias_walk_;                 // (m/s^2)^2 per second of the bias's random walk; 0: fixed
  double gate_margin_;               // m, imu.accel_gate
  bool started_ = false;
  static constexpr int kUpdatesForVelocity = 2;
  int velocity_updates_ = 0;  // registrations since the velocity was unknown
  Vector9d state_ = Vector9d::Zero();  // u, g, b

  Matrix9d covariance_ = Matrix9d::Zero();
};

}  // namespace elo
