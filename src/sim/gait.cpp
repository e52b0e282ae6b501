#include "elo/sim/gait.hpp"

#include <cmath>

namespace elo::sim {
namespace {

constexpr double kDegrees = M_PI / 180.0;

// A footfall's jolt: 1 at each of `hz` footfalls a second, falling to nearly 0 between them.
double jolt(double time, double hz) { return std::pow(std::abs(std::cos(M_PI * hz * time)), 8.0); }

}  // namespace

Eigen::Isometry3d Gait::offsetAt(double time) const {
  const double yaw = yaw_swing_deg * kDegrees * std::sin(2.0 * M_PI * yaw_swing_hz * time);
  // Rocking from one foot to the other: roll at half the step rate, pitch at the step rate.
  const double half_step = 2.0 * M_PI * 0.5 * step_hz * time;
  double roll = sway_deg * kDegrees * std::sin(half_step);
  const double pitch = 0.5 * sway_deg * kDegrees * std::sin(2.0 * half_step);
  double rise = bob_m * std::sin(2.0 * half_step);
  if (jolts) {
    const double shock = jolt(time, step_hz);
    rise = -bob_m * shock;
    roll += sway_deg * kDegrees * shock * (std::sin(half_step) >= 0.0 ? 1.0 : -1.0);
  }
  Eigen::Isometry3d offset = Eigen::Isometry3d::Identity();
  offset.linear() = (Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitZ()) * Eigen::AngleAxisd(pitch, Eigen::Vector3d::UnitY()) *
                     Eigen::AngleAxisd(roll, Eigen::Vector3d::UnitX()))
                        .toRotationMatrix();
  offset.translation().z() = rise;
  return offset;
}

Gait handheldWalk() {
  Gait gait;
  gait.yaw_swing_deg = 30.0;
  gait.yaw_swing_hz = 1.0;
  gait.sway_deg = 10.0;
  gait.bob_m = 0.04;
  gait.step_hz = 1.8;
  return gait;
}

Gait trot() {
  Gait gait;
  gait.yaw_swing_deg = 5.0;
  gait.yaw_swing_hz = 0.7;
  gait.sway_deg = 4.0;
  gait.bob_m = 0.03;
  gait.step_hz = 3.0;
  gait.jolts = true;
  return gait;
}

std::optional<Gait> gaitFromName(const std::string& name) {
  if (name == "none") return Gait();
  if (name == "walk") return handheldWalk();
  if (name == "trot") return trot();
  return std::nullopt;
}

std::vector<std::string> gaitNames() { return {"none", "walk", "trot"}; }

}  // namespace elo::sim
