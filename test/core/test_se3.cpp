#include <gtest/gtest.h>

#include "elo/pipeline/motion_prior.hpp"
#include "elo/se3.hpp"

namespace elo {
namespace {

Vector6d twist(double x, double y, double z, double rx, double ry, double rz) {
  Vector6d t;
  t << x, y, z, rx, ry, rz;
  return t;
}

TEST(SE3, ExpAndLogAreInverse) {
  for (const Vector6d& t : {twist(1, -2, 0.5, 0.1, -0.3, 0.7), twist(0.3, 0, 0, 0, 0, 1e-9),
                            twist(0, 0, 0, 0, 0, 0), twist(-4, 1, 2, 2.5, 0.2, -0.4)}) {
    EXPECT_LT((logSE3(expSE3(t)) - t).norm(), 1e-9) << t.transpose();
  }
}

TEST(SE3, ExpOfPureRotationAndTranslation) {
  const Eigen::Isometry3d turn = expSE3(twist(0, 0, 0, 0, 0, M_PI / 2));
  EXPECT_TRUE((turn * Eigen::Vector3d::UnitX()).isApprox(Eigen::Vector3d::UnitY(), 1e-12));
  const Eigen::Isometry3d shift = expSE3(twist(1, 2, 3, 0, 0, 0));
  EXPECT_TRUE(shift.translation().isApprox(Eigen::Vector3d(1, 2, 3)));
  EXPECT_NEAR(rotationAngle(expSE3(twist(0, 0, 0, 1e-7, 0, 0))), 1e-7, 1e-15);
}

TEST(MotionPrior, ConstantAccelerationExtrapolatesExactly) {
  // Speed grows by 0.1 m/s every 0.1 s: increments of 1.0, 1.01, then 1.02 m are expected.
  MotionModel model(MotionPrior::constant_acceleration);
  EXPECT_TRUE(model.predict(0.1).isApprox(Eigen::Isometry3d::Identity()));
  model.record(expSE3(twist(1.00, 0, 0, 0, 0, 0.010)), 0.1);
  model.record(expSE3(twist(1.01, 0, 0, 0, 0, 0.011)), 0.1);
  const Vector6d predicted = logSE3(model.predict(0.1));
  EXPECT_LT((predicted - twist(1.02, 0, 0, 0, 0, 0.012)).norm(), 1e-12);
  // A dropped frame: twice the time, twice the increment.
  EXPECT_LT((logSE3(model.predict(0.2)) - 2.0 * twist(1.02, 0, 0, 0, 0, 0.012)).norm(), 1e-10);
}

TEST(MotionPrior, ConstantVelocityAndNone) {
  MotionModel velocity(MotionPrior::constant_velocity);
  velocity.record(expSE3(twist(1.0, 0, 0, 0, 0, 0)), 0.1);
  velocity.record(expSE3(twist(1.2, 0, 0, 0, 0, 0)), 0.1);
  EXPECT_NEAR(velocity.predict(0.1).translation().x(), 1.2, 1e-12);
  MotionModel none(MotionPrior::none);
  none.record(expSE3(twist(1.0, 0, 0, 0, 0, 0)), 0.1);
  EXPECT_TRUE(none.predict(0.1).isApprox(Eigen::Isometry3d::Identity()));
}

}  // namespace
}  // namespace elo
