// Roll and pitch held to gravity (imu.tilt_hold_deg; docs/imu.md, "Gravity and the attitude").
//
// Over a window of kWindowSeconds of accepted scans, gravity in the odometry's world frame is what the
// accelerometers' specific force, turned into the world by the odometry's attitudes, leaves of the IMU's
// change of velocity (from the registered positions): g T = (v_end - v_start) - sum(R f dt). An attitude
// that has drifted by a rotation D turns that gravity by D. The first window's gravity is the reference;
// a later window's further than imu.tilt_hold_deg from it says the attitude has tilted by more than the
// accelerometers' bias can fake (a bias fixed to the sensor turns with it as a car turns: a consumer
// unit's 5 mg reads as up to 0.6 deg), and that excess is taken out of the attitude, a share each scan,
// by a turn about a level axis, which leaves the heading as it is.
#pragma once

#include <Eigen/Core>
#include <cstddef>
#include <deque>
#include <optional>

#include "elo/config.hpp"

namespace elo {

class TiltHold {
 public:
  explicit TiltHold(const ImuConfig& config);

  // An accepted scan at `time` (s), the IMU then at `imu_position` in the world (m), and `force` the
  // specific force integrated over the interval since the scan before, in the world frame (m/s; nullopt
  // when the IMU did not cover it, which starts the window again). Returns the turn of the world frame
  // that brings the attitude towards the reference: the identity within the band, before the reference,
  // and with the hold off (which still measures the tilt).
  Eigen::Matrix3d follow(double time, const Eigen::Vector3d& imu_position, const std::optional<Eigen::Vector3d>& force);
  // The world frame is a new one (Odometry::reset(), a new mount): the reference is taken again.
  void reset();

  // deg: the latest window's gravity against the reference; nullopt before there are both.
  std::optional<double> tiltDeg() const { return tilt_deg_; }
  // Scans whose attitude was turned towards gravity.
  size_t heldCount() const { return held_; }

 private:
  struct Scan {
    double time;
    Eigen::Vector3d imu_position;
    Eigen::Vector3d force;  // since the scan before
  };
  // The IMU's velocity at window_[i], from the positions of the scans either side.
  Eigen::Vector3d velocityAt(size_t i) const;
  // Gravity's direction over the window, once it spans kWindowSeconds.
  std::optional<Eigen::Vector3d> windowGravity() const;

  double band_;  // rad; 0: the hold is off
  std::deque<Scan> window_;
  std::optional<Eigen::Vector3d> reference_;  // gravity's direction, unit
  std::optional<double> tilt_deg_;
  size_t held_ = 0;
};

}  // namespace elo
