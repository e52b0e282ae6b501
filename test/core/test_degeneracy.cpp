// Degeneracy handling: the unit-consistent eigen-analysis of the Hessian, the step restricted to the
// constrained directions, and registration on an exact corridor whose forward translation nothing
// constrains.
#include <gtest/gtest.h>

#include "analytic_scene.hpp"
#include "elo/pipeline/degeneracy.hpp"
#include "elo/pipeline/odometry.hpp"

namespace elo {
namespace {

// J^T J of unit-weight point-to-plane rows n^T [I, -[p]x] (the Jacobian's layout, see correspondences.cpp).
Matrix6d hessianOf(const std::vector<std::pair<Eigen::Vector3d, Eigen::Vector3d>>& points_and_normals) {
  Matrix6d H = Matrix6d::Zero();
  for (const auto& [point, normal] : points_and_normals) {
    Vector6d J;
    J << normal, point.cross(normal);
    H += J * J.transpose();
  }
  return H / static_cast<double>(points_and_normals.size());
}

// A box room of half size `half` around the origin: points on all six faces, well spread.
Matrix6d roomHessian(const Eigen::Vector3d& half) {
  std::vector<std::pair<Eigen::Vector3d, Eigen::Vector3d>> samples;
  for (int axis = 0; axis < 3; ++axis) {
    for (const double side : {-1.0, 1.0}) {
      const int u = (axis + 1) % 3;
      const int v = (axis + 2) % 3;
      for (const double a : {-0.8, -0.3, 0.3, 0.8}) {
        for (const double b : {-0.8, -0.3, 0.3, 0.8}) {
          Eigen::Vector3d point = Eigen::Vector3d::Zero();
          point[axis] = side * half[axis];
          point[u] = a * half[u];
          point[v] = b * half[v];
          samples.emplace_back(point, -side * Eigen::Vector3d::Unit(axis));
        }
      }
    }
  }
  return hessianOf(samples);
}

TEST(Degeneracy, EigenvaluesAreSharesOfTheConstraintWhateverTheScale) {
  // A cube room: every translation gets a third of the normals' energy, whatever its size.
  for (const double size : {2.0, 50.0}) {
    const std::optional<Degeneracy> degeneracy = analyseDegeneracy(roomHessian(Eigen::Vector3d::Constant(size)), 0.01);
    ASSERT_TRUE(degeneracy);
    EXPECT_NEAR(degeneracy->eigenvalues.sum(), 2.0, 1e-12);
    EXPECT_EQ(degeneracy->count, 0);
    Vector6d forward = Vector6d::Zero();
    forward[0] = 1.0;
    const double share = forward.dot(degeneracy->eigenvectors * degeneracy->eigenvalues.asDiagonal() *
                                     degeneracy->eigenvectors.transpose() * forward);
    EXPECT_NEAR(share, 1.0 / 3.0, 1e-12) << "size " << size;
  }
}

TEST(Degeneracy, ACorridorLacksItsAxisAndTheStepLeavesItAlone) {
  // Walls at y = +-3, floor and ceiling at z = +-2: nothing faces along x.
  std::vector<std::pair<Eigen::Vector3d, Eigen::Vector3d>> samples;
  for (double x = -20.0; x <= 20.0; x += 2.5) {
    for (const double t : {-0.7, 0.0, 0.7}) {
      samples.push_back({{x, 3.0, 2.0 * t}, -Eigen::Vector3d::UnitY()});
      samples.push_back({{x, -3.0, 2.0 * t}, Eigen::Vector3d::UnitY()});
      samples.push_back({{x, 3.0 * t, -2.0}, Eigen::Vector3d::UnitZ()});
      samples.push_back({{x, 3.0 * t, 2.0}, -Eigen::Vector3d::UnitZ()});
    }
  }
  const Matrix6d H = hessianOf(samples);
  const std::optional<Degeneracy> degeneracy = analyseDegeneracy(H, 0.01);
  ASSERT_TRUE(degeneracy);
  ASSERT_EQ(degeneracy->count, 1);
  EXPECT_NEAR(degeneracy->eigenvalues[0], 0.0, 1e-12);
  EXPECT_NEAR(std::abs(degeneracy->eigenvectors(0, 0)), 1.0, 1e-9);
  EXPECT_EQ(degeneracy->describe(), "x");

  // A gradient with a forward component: the step solves the rest and leaves x alone, but for the 1e-4 of
  // its pull that the capped prior information lets through. Along the constrained directions the prior
  // (tau^4 / share^3) moves the steps by (tau / share)^4 of theirs: 1% of the largest along the corridor's
  // most weakly constrained one.
  const Vector6d truth = (Vector6d() << 0.3, 0.02, -0.01, 0.001, 0.002, -0.003).finished();
  const Vector6d gradient = -H * truth + 0.05 * Vector6d::Unit(0);
  const std::optional<Vector6d> step = priorWeightedStep(*degeneracy, H, gradient, Vector6d::Zero());
  ASSERT_TRUE(step);
  EXPECT_NEAR((*step)[0], 0.0, 1e-4 * 0.05);
  EXPECT_LT(((*step).tail<5>() - truth.tail<5>()).cwiseAbs().maxCoeff(), 0.02 * truth.tail<5>().cwiseAbs().maxCoeff());
  // Already 0.2 m off the prior along x, the step takes it back; along the rest the scan decides.
  const std::optional<Vector6d> back = priorWeightedStep(*degeneracy, H, -H * truth, 0.2 * Vector6d::Unit(0));
  ASSERT_TRUE(back);
  EXPECT_NEAR((*back)[0], -0.2, 1e-6);

  // Its covariance is the prior's along x, and H^-1 scaled on the others.
  const Matrix6d covariance = degeneracy->covariance(H, 1e-6, 4.0);
  EXPECT_NEAR(covariance(0, 0), 4.0, 1e-9);
  const Eigen::Matrix<double, 5, 5> constrained = H.bottomRightCorner<5, 5>();
  EXPECT_LT((covariance.bottomRightCorner<5, 5>() - 1e-6 * constrained.inverse()).cwiseAbs().maxCoeff(), 1e-15);
  // The motion prior keeps its x component and (but for 1% of the largest) drops the others.
  EXPECT_LT((degeneracy->priorShare() * truth - 0.3 * Vector6d::Unit(0)).cwiseAbs().maxCoeff(),
            0.02 * truth.tail<5>().cwiseAbs().maxCoeff());

  // Off (threshold 0): a singular Hessian gives no step.
  const std::optional<Degeneracy> off = analyseDegeneracy(H, 0.0);
  ASSERT_TRUE(off);
  EXPECT_EQ(off->count, 0);
  const std::optional<Vector6d> unsolved = priorWeightedStep(*off, H, gradient, Vector6d::Zero());
  EXPECT_TRUE(!unsolved || std::abs((*unsolved)[0]) > 1.0) << "no step, or a wild one along x";
}

TEST(Degeneracy, AScrewAlongACurveIsNamedByBothAxes) {
  Degeneracy degeneracy;
  degeneracy.count = 1;
  degeneracy.eigenvectors.col(0) << 0.8, 0.0, 0.0, 0.0, 0.0, 0.6;
  EXPECT_EQ(degeneracy.describe(), "x+yaw");
}

TEST(Degeneracy, WithoutAnyConstraintThereIsNothingToAnalyse) {
  EXPECT_FALSE(analyseDegeneracy(Matrix6d::Zero(), 0.01));
}

TEST(Degeneracy, ThePriorContinuesAtConstantVelocityAlongTheDegenerateDirections) {
  MotionModel motion(MotionPrior::constant_acceleration);
  const auto step = [](double x, double y) { return Eigen::Isometry3d(Eigen::Translation3d(x, y, 0.0)); };
  motion.record(step(1.0, 0.10), 0.1);
  motion.record(step(1.1, 0.20), 0.1);  // accelerating along x and y
  Degeneracy degeneracy;  // eigenvectors are the identity: x has no share, the rest plenty
  degeneracy.eigenvalues << 0.0, 1.0, 1.0, 1.0, 1.0, 1.0;
  degeneracy.threshold = 0.01;
  degeneracy.count = 1;
  motion.holdVelocityAlong(degeneracy.priorShare());
  const Eigen::Vector3d predicted = motion.predict(0.1).translation();
  EXPECT_NEAR(predicted.x(), 1.1, 1e-12) << "x: the last increment again";
  EXPECT_NEAR(predicted.y(), 0.3, 1e-9) << "y: still extrapolated (but for (tau / share)^4 = 1e-8 of it)";
}

using test::pose;
// An open-topped corridor: the ground and two parallel walls longer than the sensor's reach.
test::Scene corridorScene() {
  test::Scene scene;
  scene.boxes = {{{-400, 6, -1.73}, {400, 7, 8}}, {{-400, -7, -1.73}, {400, -6, 8}}};
  return scene;
}

// Registers a scan from `truth` with an informed motion prior of standing still (the guess is identity):
// two scans from the origin give the constant-velocity prior its history, then the scan from `truth`.
FrameResult registerStandingStillPrior(const test::Scene& scene, const Eigen::Isometry3d& truth) {
  Config config;
  config.model.motion_prior = MotionPrior::constant_velocity;
  // From standing still to metres a second within one scan: beyond any vehicle (motion.max_acceleration
  // would refuse it, docs/robustness.md); what these tests ask is what the registration makes of it.
  config.motion.max_acceleration = 1e3;
  Odometry odometry(config);
  for (const double stamp : {0.0, 0.1}) {
    const PointCloud still = test::scanScene(scene, config.sensor, Eigen::Isometry3d::Identity(), stamp).cloud;
    EXPECT_TRUE(odometry.process(still).processed);
  }
  return odometry.process(test::scanScene(scene, config.sensor, truth, 0.2).cloud);
}

TEST(Degeneracy, TheCorridorKeepsTheInitialGuessAlongItsAxisAndFindsTheRest) {
  // An informed prior is centimetres off where the scene constrains the motion; along the corridor it
  // can be anything.
  const Eigen::Isometry3d truth = pose(0.8, 0.03, 0.01, 0.05, -0.1, 0.2);
  const FrameResult result = registerStandingStillPrior(corridorScene(), truth);
  ASSERT_TRUE(result.processed);
  const RegistrationResult& registration = result.registration;
  EXPECT_FALSE(registration.failed);
  EXPECT_TRUE(registration.converged);
  ASSERT_EQ(registration.degeneracy.count, 1) << registration.degeneracy.eigenvalues.transpose();
  EXPECT_EQ(registration.degeneracy.describe(), "x");
  EXPECT_GT(std::abs(registration.degeneracy.eigenvectors(0, 0)), 0.999);
  // Along the corridor, the initial guess (the prior: identity); across it, the truth.
  const Eigen::Vector3d error = result.delta.translation() - truth.translation();
  EXPECT_LT(std::abs(result.delta.translation().x()), 1e-3) << result.delta.translation().transpose();
  EXPECT_LT(std::abs(error.y()), 1e-3);
  EXPECT_LT(std::abs(error.z()), 1e-3);
  EXPECT_LT(rotationAngle(result.delta.inverse() * truth) * 180.0 / M_PI, 0.01);
}

TEST(Degeneracy, TheStreetHasNoDegenerateDirection) {
  const Eigen::Isometry3d truth = pose(0.05, 0.03, 0.01, 0.05, -0.1, 0.2);
  const FrameResult result = registerStandingStillPrior(test::streetScene(), truth);
  ASSERT_TRUE(result.processed);
  EXPECT_EQ(result.registration.degeneracy.count, 0) << result.registration.degeneracy.eigenvalues.transpose();
  EXPECT_GT(result.registration.degeneracy.eigenvalues[0], 2.0 * RegistrationConfig().degeneracy_threshold);
}

TEST(Degeneracy, APriorOffAlongAConstrainedDirectionIsCorrectedNotKept) {
  // A prior 0.4 m off along the street: under the 0.1 m robust kernel, the surfaces facing the motion
  // (the wall across the street, car ends, poles) carry little weight and the weighted Hessian finds x
  // degenerate; the geometry does not, so x is solved.
  const Eigen::Isometry3d truth = pose(0.4, 0.0, 0.0, 0.0, 0.0, 0.0);
  const FrameResult result = registerStandingStillPrior(test::streetScene(), truth);
  ASSERT_TRUE(result.processed);
  EXPECT_EQ(result.registration.degeneracy.count, 0) << result.registration.degeneracy.eigenvalues.transpose();
  EXPECT_LT((result.delta.translation() - truth.translation()).norm(), 1e-3) << result.delta.translation().transpose();
}

TEST(Degeneracy, WithoutAnInformedPriorEveryDirectionIsSolved) {
  // No motion history: the guess is identity, which may be a metre off (a start at speed), and there is
  // no prior to keep.
  Config config;
  config.model.motion_prior = MotionPrior::none;
  Odometry odometry(config);
  const test::Scene scene = corridorScene();
  odometry.process(test::scanScene(scene, config.sensor, Eigen::Isometry3d::Identity(), 0.0).cloud);
  const Eigen::Isometry3d truth = pose(0.8, 0.0, 0.0, 0.0, 0.0, 0.0);
  const FrameResult result = odometry.process(test::scanScene(scene, config.sensor, truth, 0.1).cloud);
  ASSERT_TRUE(result.processed);
  EXPECT_EQ(result.registration.degeneracy.count, 0);
  EXPECT_LT(result.registration.degeneracy.eigenvalues[0], config.registration.degeneracy_threshold)
      << "the analysis still reports the weak direction";
}

}  // namespace
}  // namespace elo
