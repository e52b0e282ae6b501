// Roll and pitch held to gravity (TiltHold, imu.tilt_hold_deg; docs/imu.md): on an analytic drive in a
// level world (a car going round a 20 m circle at 5 m/s, bobbing), the exact specific force and positions
// read no tilt; an odometry whose attitude then tilts by 3 deg, its increments and forces turned alike,
// reads 3 deg, and applying the hold's turns brings it back to the band without turning the heading; a gap
// in the IMU starts the window again; reset() takes the reference again.
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <optional>

#include "elo/imu/tilt_hold.hpp"

namespace elo {
namespace {

constexpr double kPeriod = 0.1;  // s between scans
constexpr double kRadius = 20.0;
constexpr double kTurnRate = 0.25;  // rad/s: 5 m/s round the circle
const Eigen::Vector3d kGravity(0.0, 0.0, -9.81);

Eigen::Vector3d truePosition(double t) {
  return {kRadius * std::cos(kTurnRate * t), kRadius * std::sin(kTurnRate * t), 0.05 * std::sin(6.0 * t)};
}

Eigen::Vector3d trueVelocity(double t) {
  return {-kRadius * kTurnRate * std::sin(kTurnRate * t), kRadius * kTurnRate * std::cos(kTurnRate * t),
          0.3 * std::cos(6.0 * t)};
}

ImuConfig withBand(double degrees) {
  ImuConfig config;
  config.tilt_hold_deg = degrees;
  return config;
}

// What the odometry hands the hold, scan by scan: its positions and its world-frame forces, both through
// an attitude off the truth by `drift` (a rotation of its world), which the hold's turns correct.
class Drive {
 public:
  explicit Drive(TiltHold& hold) : hold_(hold) {}

  // The next scan; `imu_covered` false for an interval the IMU left out. Returns the hold's turn.
  Eigen::Matrix3d next(bool imu_covered = true) {
    const double t0 = scan_ * kPeriod;
    const double t1 = t0 + kPeriod;
    // The integral of the specific force (a - g) over the interval, exactly.
    const Eigen::Vector3d force = trueVelocity(t1) - trueVelocity(t0) - kGravity * kPeriod;
    position_ += drift * (truePosition(t1) - truePosition(t0));
    ++scan_;
    const Eigen::Matrix3d turn = hold_.follow(t1, position_, imu_covered ? std::optional<Eigen::Vector3d>(drift * force)
                                                                         : std::nullopt);
    drift = turn * drift;
    return turn;
  }

  Eigen::Matrix3d drift = Eigen::Matrix3d::Identity();

 private:
  TiltHold& hold_;
  Eigen::Vector3d position_ = truePosition(0.0);
  int scan_ = 0;
};

TEST(TiltHold, ALevelDriveReadsNoTiltAndTurnsNothing) {
  TiltHold hold(withBand(1.0));
  Drive drive(hold);
  for (int i = 0; i < 100; ++i) {
    EXPECT_TRUE(drive.next().isIdentity(0.0));
    EXPECT_FALSE(hold.tiltDeg()) << "no reference before the window spans 10 s: scan " << i;
  }
  for (int i = 0; i < 300; ++i) EXPECT_TRUE(drive.next().isIdentity(0.0));
  ASSERT_TRUE(hold.tiltDeg());
  // The velocities are central differences of the positions: exact to the bob's third derivative.
  EXPECT_LT(*hold.tiltDeg(), 0.01);
  EXPECT_EQ(hold.heldCount(), 0u);
}

TEST(TiltHold, ATiltedAttitudeIsBroughtBackToTheBandWithoutTurningTheHeading) {
  TiltHold hold(withBand(1.0));
  Drive drive(hold);
  for (int i = 0; i < 150; ++i) drive.next();
  ASSERT_TRUE(hold.tiltDeg());
  // The odometry's world tilts by 3 deg about a level axis and turns by 10 deg of heading.
  const Eigen::Matrix3d heading(Eigen::AngleAxisd(10.0 * M_PI / 180.0, Eigen::Vector3d::UnitZ()));
  drive.drift = heading * Eigen::AngleAxisd(3.0 * M_PI / 180.0, Eigen::Vector3d(1.0, 1.0, 0.0).normalized());
  double largest_tilt = 0.0;
  for (int i = 0; i < 400; ++i) {
    const Eigen::Matrix3d turn = drive.next();
    if (turn.isIdentity(0.0)) continue;
    const Eigen::Vector3d axis = Eigen::AngleAxisd(turn).axis();
    EXPECT_LT(std::abs(axis.z()), 0.06) << "a turn about a level axis (within the tilt), scan " << i;
    largest_tilt = std::max(largest_tilt, *hold.tiltDeg());
  }
  // The window's gravity is its ten seconds' mean: the hold acts once the tilted part takes it past the band.
  EXPECT_GT(largest_tilt, 1.2) << "the window saw the tilt";
  EXPECT_GT(hold.heldCount(), 100u);
  // Back to the band: the attitude's tilt, gravity through it against the truth's.
  const double tilt = std::acos(std::clamp((drive.drift * kGravity).normalized().dot(kGravity.normalized()), -1.0, 1.0));
  EXPECT_NEAR(tilt * 180.0 / M_PI, 1.0, 0.05);
  EXPECT_NEAR(*hold.tiltDeg(), 1.0, 0.05);
  // The heading is the drift's yaw, as it was.
  const Eigen::Vector3d forward = drive.drift * Eigen::Vector3d::UnitX();
  EXPECT_NEAR(std::atan2(forward.y(), forward.x()) * 180.0 / M_PI, 10.0, 0.1);
}

TEST(TiltHold, OffItMeasuresTheTiltAndTurnsNothing) {
  TiltHold hold(withBand(0.0));
  Drive drive(hold);
  for (int i = 0; i < 150; ++i) drive.next();
  drive.drift = Eigen::Matrix3d(Eigen::AngleAxisd(3.0 * M_PI / 180.0, Eigen::Vector3d::UnitY()));
  for (int i = 0; i < 250; ++i) EXPECT_TRUE(drive.next().isIdentity(0.0));
  ASSERT_TRUE(hold.tiltDeg());
  EXPECT_NEAR(*hold.tiltDeg(), 3.0, 0.01);
  EXPECT_EQ(hold.heldCount(), 0u);
}

TEST(TiltHold, AGapInTheImuStartsTheWindowAgain) {
  TiltHold hold(withBand(1.0));
  Drive drive(hold);
  for (int i = 0; i < 150; ++i) drive.next();
  drive.next(false);
  drive.drift = Eigen::Matrix3d(Eigen::AngleAxisd(3.0 * M_PI / 180.0, Eigen::Vector3d::UnitY()));
  // Ten seconds to span the window again: until then the tilt is not measured, nothing is turned.
  for (int i = 0; i < 95; ++i) EXPECT_TRUE(drive.next().isIdentity(0.0)) << "scan " << i << " after the gap";
  for (int i = 0; i < 300; ++i) drive.next();
  EXPECT_GT(hold.heldCount(), 0u);
  EXPECT_NEAR(*hold.tiltDeg(), 1.0, 0.05) << "the reference kept through the gap";
}

TEST(TiltHold, ResetTakesTheReferenceAgain) {
  TiltHold hold(withBand(1.0));
  Drive drive(hold);
  for (int i = 0; i < 150; ++i) drive.next();
  hold.reset();
  EXPECT_FALSE(hold.tiltDeg());
  // The new world is tilted from its start: its gravity is the new reference.
  drive.drift = Eigen::Matrix3d(Eigen::AngleAxisd(3.0 * M_PI / 180.0, Eigen::Vector3d::UnitX()));
  for (int i = 0; i < 300; ++i) EXPECT_TRUE(drive.next().isIdentity(0.0));
  EXPECT_LT(*hold.tiltDeg(), 0.01);
}

}  // namespace
}  // namespace elo
