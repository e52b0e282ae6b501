// The initial guess of the registration (Sec. III-A): the motion of the last two increments
// extrapolated at constant acceleration in the Lie algebra, scaled by the time since the last scan so
// that dropped frames and irregular rates are predicted right.
#pragma once

#include "elo/config.hpp"
#include "elo/se3.hpp"

namespace elo {

class MotionModel {
 public:
  explicit MotionModel(MotionPrior prior) : prior_(prior) {}

  // The predicted T^{t-1}_t for a scan `dt` seconds after the previous one.
  Eigen::Isometry3d predict(double dt) const;
  // Records the estimated increment T^{t-1}_t that spanned `dt` seconds.
  void record(const Eigen::Isometry3d& increment, double dt);
  // The increment just recorded came from a registration that kept the prediction in the part of a twist
  // `projector` keeps (Degeneracy::priorShare: all of it along a degenerate direction): its acceleration
  // there was extrapolated, not observed. Zeroing that part continues the motion at constant velocity;
  // extrapolating it again, scan after scan, would integrate an acceleration nobody saw (1 mm/scan^2 is
  // 5 m after 10 s at 10 Hz).
  void holdVelocityAlong(const Matrix6d& projector);
  void reset() { history_ = 0; }
  // Whether any increment was recorded since the last reset: before it the motion is unknown, not zero
  // (Odometry searches it: start_search.hpp).
  bool known() const { return history_ > 0; }
  // The velocity of the increment recorded last, whatever the prior; zero before any.
  const Vector6d& latestVelocity() const { return latest_velocity_; }
  // The velocity (twist per second) of the increment recorded last; zero before any. What a sweep is
  // deskewed under before it is registered: the constant-acceleration extrapolation doubles the noise of
  // the registrations it extrapolates, and the deskew feeds that noise back into the next registration
  // (on the real HDL-64E scans its registrations stopped converging).
  Vector6d velocity() const { return prior_ == MotionPrior::none || history_ == 0 ? Vector6d::Zero() : latest_velocity_; }
  // Whether predictions come from the recorded motion of the configured prior (rather than identity or
  // a shorter history): a registration may then start from a tight robust kernel.
  bool informed() const { return prior_ == MotionPrior::none ? false : history_ >= requiredHistory(); }

 private:
  int requiredHistory() const { return prior_ == MotionPrior::constant_acceleration ? 2 : 1; }

  MotionPrior prior_;
  int history_ = 0;            // how many of the velocities below are known
  Vector6d latest_velocity_;   // twist per second of the last increment
  Vector6d previous_velocity_; // ... and of the one before
};

}  // namespace elo
