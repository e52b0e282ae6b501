#include "elo/pipeline/motion_prior.hpp"

namespace elo {

Eigen::Isometry3d MotionModel::predict(double dt) const {
  if (prior_ == MotionPrior::none || history_ == 0 || !(dt > 0.0)) return Eigen::Isometry3d::Identity();
  Vector6d velocity = latest_velocity_;
  if (prior_ == MotionPrior::constant_acceleration && history_ >= 2) {
    velocity = 2.0 * latest_velocity_ - previous_velocity_;  // xi_t = 2 xi_{t-1} - xi_{t-2}, per second
  }
  return expSE3(velocity * dt);
}

void MotionModel::record(const Eigen::Isometry3d& increment, double dt) {
  if (!(dt > 0.0)) return;
  previous_velocity_ = latest_velocity_;
  latest_velocity_ = logSE3(increment) / dt;
  history_ = history_ < 2 ? history_ + 1 : 2;
}

void MotionModel::holdVelocityAlong(const Matrix6d& projector) {
  if (history_ < 2) return;
  previous_velocity_ += projector * (latest_velocity_ - previous_velocity_);
}

}  // namespace elo
