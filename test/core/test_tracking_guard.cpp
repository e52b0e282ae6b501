// The tracking guard (tracking_guard.hpp) on registrations made up to lie just inside or just beyond each
// bound: what the platform can do, and what the scans before it found.
#include <gtest/gtest.h>

#include <cmath>

#include "elo/pipeline/tracking_guard.hpp"

namespace elo {
namespace {

constexpr double kDt = 0.1;

// A registration that moved the sensor `forward` metres along x and turned it `yaw_deg`, with `inliers`
// non-ground inliers.
RegistrationResult registration(double forward, double yaw_deg = 0.0, int inliers = 1000) {
  RegistrationResult result;
  result.model_from_scan.translation().x() = forward;
  result.model_from_scan.linear() = Eigen::AngleAxisd(yaw_deg * M_PI / 180.0, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  result.last.nonground.inliers = inliers;
  result.last.ground.inliers = 5000;
  return result;
}

TEST(TrackingGuard, SpeedAndTurnRateBounds) {
  const TrackingGuard guard{Config()};  // 40 m/s, 360 deg/s
  EXPECT_EQ(guard.refusal(registration(3.9), kDt), "");
  EXPECT_EQ(guard.refusal(registration(4.1), kDt), refusal::kTooFast);
  EXPECT_EQ(guard.refusal(registration(0.1, 35.0), kDt), "");
  EXPECT_EQ(guard.refusal(registration(0.1, 37.0), kDt), refusal::kTurnsTooFast);
  RegistrationResult failed = registration(1.0);
  failed.failed = true;
  EXPECT_EQ(guard.refusal(failed, kDt), refusal::kFailed);
}

// 20 m/s^2 over 0.1 s is 2 m/s, plus 2 x 10 ms / 0.1 s = 20 % of the speed for the stamps' error.
TEST(TrackingGuard, TheVelocityChangeIsHeldAgainstTheOneAcceptedLast) {
  TrackingGuard guard{Config()};
  EXPECT_EQ(guard.refusal(registration(3.0), kDt), "") << "nothing accepted yet: no acceleration to check";
  guard.accept(registration(1.0), kDt);  // 10 m/s
  EXPECT_EQ(guard.refusal(registration(1.39), kDt), "");  // 13.9 m/s: within 2 + 2 m/s
  EXPECT_EQ(guard.refusal(registration(1.41), kDt), refusal::kAccelerates);
  EXPECT_EQ(guard.refusal(registration(0.61), kDt), "");
  EXPECT_EQ(guard.refusal(registration(0.59), kDt), refusal::kAccelerates);
  guard.reset();
  EXPECT_EQ(guard.refusal(registration(3.0), kDt), "") << "a restarted model holds nothing against it";
}

TEST(TrackingGuard, InliersThatCollapseAgainstTheRecentOnesAreRefused) {
  TrackingGuard guard{Config()};  // 30 % of the median of the last 10
  EXPECT_EQ(guard.refusal(registration(1.0, 0.0, 10), kDt), "") << "no history yet";
  for (int inliers : {900, 1000, 1100}) guard.accept(registration(1.0, 0.0, inliers), kDt);
  EXPECT_EQ(guard.refusal(registration(1.0, 0.0, 301), kDt), "");
  EXPECT_EQ(guard.refusal(registration(1.0, 0.0, 299), kDt), refusal::kInliersCollapsed);
}

}  // namespace
}  // namespace elo
