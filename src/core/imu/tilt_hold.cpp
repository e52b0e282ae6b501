#include "elo/imu/tilt_hold.hpp"

#include <Eigen/Geometry>
#include <cmath>

namespace elo {

namespace {

// s: long enough that the registered positions' noise (a few mm, differenced over two scans) leaves under
// 0.02 deg of gravity's direction, short enough to follow a drift of the attitude.
constexpr double kWindowSeconds = 10.0;
// The share of the tilt beyond the band taken out at each scan: a second to bring it back at 10 Hz, no
// step a registration would notice.
constexpr double kShareEachScan = 0.2;

}  // namespace

TiltHold::TiltHold(const ImuConfig& config) : band_(config.tilt_hold_deg * M_PI / 180.0) {}

Eigen::Matrix3d TiltHold::follow(double time, const Eigen::Vector3d& imu_position,
                                 const std::optional<Eigen::Vector3d>& force) {
  if (!force) window_.clear();
  window_.push_back({time, imu_position, force.value_or(Eigen::Vector3d::Zero())});
  // The window spans kWindowSeconds between its second scan and its last but one, where the velocities are.
  while (window_.size() > 4 && window_[window_.size() - 2].time - window_[2].time >= kWindowSeconds) {
    window_.pop_front();
  }
  const std::optional<Eigen::Vector3d> gravity = windowGravity();
  if (!gravity) return Eigen::Matrix3d::Identity();
  if (!reference_) reference_ = *gravity;
  const Eigen::Vector3d axis = gravity->cross(*reference_);
  const double tilt = std::atan2(axis.norm(), gravity->dot(*reference_));
  tilt_deg_ = tilt * 180.0 / M_PI;
  if (band_ <= 0.0 || tilt <= band_) return Eigen::Matrix3d::Identity();
  ++held_;
  // Turning about gravity x reference moves gravity towards the reference; the window's world vectors
  // turn with the world.
  const Eigen::Matrix3d turn = Eigen::AngleAxisd(kShareEachScan * (tilt - band_), axis.normalized()).toRotationMatrix();
  for (Scan& scan : window_) {
    scan.imu_position = turn * scan.imu_position;
    scan.force = turn * scan.force;
  }
  return turn;
}

Eigen::Vector3d TiltHold::velocityAt(size_t i) const {
  return (window_[i + 1].imu_position - window_[i - 1].imu_position) / (window_[i + 1].time - window_[i - 1].time);
}

std::optional<Eigen::Vector3d> TiltHold::windowGravity() const {
  // The velocities at the second scan and the last but one, and the force between them.
  if (window_.size() < 4) return std::nullopt;
  const size_t first = 1;
  const size_t last = window_.size() - 2;
  const double span = window_[last].time - window_[first].time;
  if (span < kWindowSeconds) return std::nullopt;
  Eigen::Vector3d force = Eigen::Vector3d::Zero();
  for (size_t i = first + 1; i <= last; ++i) force += window_[i].force;
  const Eigen::Vector3d gravity = (velocityAt(last) - velocityAt(first) - force) / span;
  return gravity.normalized();
}

void TiltHold::reset() {
  window_.clear();
  reference_.reset();
  tilt_deg_.reset();
}

}  // namespace elo
