// Gauss-Newton registration and the whole pipeline on exact scans of the analytic street.
#include <gtest/gtest.h>

#include "analytic_scene.hpp"
#include "elo/pipeline/odometry.hpp"

namespace elo {
namespace {

using test::pose;
double translationErrorMm(const Eigen::Isometry3d& a, const Eigen::Isometry3d& b) {
  return (a.inverse() * b).translation().norm() * 1000.0;
}
double rotationErrorDeg(const Eigen::Isometry3d& a, const Eigen::Isometry3d& b) {
  return rotationAngle(a.inverse() * b) * 180.0 / M_PI;
}

// Registers a scan from `truth` against one from the origin, starting from identity.
FrameResult registerPair(Config config, const Eigen::Isometry3d& truth) {
  config.model.motion_prior = MotionPrior::none;
  const test::Scene scene = test::streetScene();
  Odometry odometry(config);
  EXPECT_TRUE(odometry.process(test::scanScene(scene, config.sensor, Eigen::Isometry3d::Identity(), 0.0).cloud).processed);
  return odometry.process(test::scanScene(scene, config.sensor, truth, 0.1).cloud);
}

TEST(Registration, GaussNewtonRecoversAKnownMotionToAMillimetre) {
  const Eigen::Isometry3d truth = pose(0.6, 0.15, 0.03, 0.3, -0.4, 1.5);
  const FrameResult result = registerPair(Config(), truth);
  ASSERT_TRUE(result.processed);
  EXPECT_TRUE(result.registration.converged);
  EXPECT_LT(translationErrorMm(result.delta, truth), 1.0);
  EXPECT_LT(rotationErrorDeg(result.delta, truth), 0.01);
  EXPECT_GT(result.registration.last.nonground.inliers, 5000);
  EXPECT_GT(result.registration.last.ground.inliers, 5000);
  EXPECT_GT(result.registration.weight, 0.0);
  EXPECT_LE(result.registration.weight, 0.7);
}

// Weighing near correspondences less (registration.near_weight_range) changes how much each one counts,
// not where the minimum of an exact scene lies; and it does change the sums.
TEST(Registration, NearWeightingKeepsAnExactSceneExact) {
  const Eigen::Isometry3d truth = pose(0.6, 0.15, 0.03, 0.3, -0.4, 1.5);
  Config config;
  config.registration.near_weight_range = 45.0;
  const FrameResult weighed = registerPair(config, truth);
  ASSERT_TRUE(weighed.processed);
  EXPECT_TRUE(weighed.registration.converged);
  EXPECT_LT(translationErrorMm(weighed.delta, truth), 1.0);
  EXPECT_LT(rotationErrorDeg(weighed.delta, truth), 0.01);
  const FrameResult alike = registerPair(Config(), truth);
  EXPECT_NE(weighed.delta.matrix(), alike.delta.matrix());
}

TEST(Registration, EveryTableIIVariantConvergesAndTheGroundTermHelps) {
  // On exact planes the spherical image of all points also finds the motion. Without the ground
  // (non-ground SRI alone) roll and pitch rest on a few car roofs and the estimate is visibly worse:
  // the gap the BEV ground term closes. Where fusion beats the all-points image (noisy, sparse ground,
  // feature-poor scenes) is measured by the simulator's ablation.
  const Eigen::Isometry3d truth = pose(0.4, -0.1, 0.0, 0.0, 0.0, 1.0);
  const FrameResult fused = registerPair(Config(), truth);
  EXPECT_LT(rotationErrorDeg(fused.delta, truth), 0.01);

  Config all_points;
  all_points.registration.terms = CostTerms::spherical_all;
  const FrameResult spherical = registerPair(all_points, truth);
  EXPECT_LT(translationErrorMm(spherical.delta, truth), 5.0);
  EXPECT_LT(rotationErrorDeg(spherical.delta, truth), 0.05);
  EXPECT_DOUBLE_EQ(spherical.registration.weight, 1.0);

  Config nonground;
  nonground.registration.terms = CostTerms::spherical_nonground;
  const FrameResult walls = registerPair(nonground, truth);
  EXPECT_LT(translationErrorMm(walls.delta, truth), 30.0);
  EXPECT_LT(rotationErrorDeg(walls.delta, truth), 0.5);
  EXPECT_GT(rotationErrorDeg(walls.delta, truth), 5.0 * rotationErrorDeg(fused.delta, truth));
}

TEST(Registration, ResultsAreIdenticalForAnyThreadCount) {
  const Eigen::Isometry3d truth = pose(0.5, 0.05, 0.0, 0.1, 0.2, -0.8);
  Config one;
  one.runtime.threads = 1;
  Config two;
  two.runtime.threads = 2;
  const FrameResult a = registerPair(one, truth);
  const FrameResult b = registerPair(two, truth);
  EXPECT_EQ(a.delta.matrix(), b.delta.matrix());
  EXPECT_EQ(a.registration.iterations, b.registration.iterations);
}

// A cost whose Gauss-Newton steps shrink by a fixed ratio, as reweighted Gauss-Newton's do: every
// linearisation asks for (1 - ratio) of the way back to the identity. The pose stays a screw motion along
// x (translation along the rotation axis), so the steps compose exactly.
class ShrinkingSteps : public Backend {
 public:
  explicit ShrinkingSteps(double ratio) : ratio_(ratio) {}

  NormalEquations linearize(const Eigen::Isometry3d& model_from_scan, double) override {
    const Eigen::AngleAxisd rotation(model_from_scan.rotation());
    Vector6d error;
    error << model_from_scan.translation(), rotation.angle() * rotation.axis();
    NormalEquations sums;
    sums.nonground.candidates = sums.nonground.inliers = 100;
    sums.nonground.JtJ = 100.0 * Matrix6d::Identity();
    sums.nonground.Jte = 100.0 * (1.0 - ratio_) * error;
    ++linearizations;
    return sums;
  }

  int linearizations = 0;

  const char* name() const override { return "shrinking steps"; }
  size_t projectScan(const PointCloud&, float, const SweepMotion&) override { return 0; }
  void deskewScan(const Vector6d&) override {}
  void segmentGround() override {}
  void estimateNormals() override {}
  void buildGroundMap() override {}
  void updateModel(const Eigen::Isometry3d&, float) override {}
  void resetModel() override {}
  const ScanImage& scan() override { return scan_; }
  const BevImage& scanGround() override { return ground_; }
  const Model& model() override { return model_; }
  void setMap(std::shared_ptr<const MapCloud>) override {}
  void renderMap(const std::vector<int32_t>&, const Eigen::Isometry3d&) override {}
  NormalEquations linearizeMap(const Eigen::Isometry3d&, double) override { return {}; }
  const Model& mapModel() override { return model_; }

 private:
  double ratio_;
  ScanImage scan_;
  BevImage ground_;
  Model model_;
};

RegistrationResult registerShrinking(ShrinkingSteps& backend) {
  RegistrationConfig config;  // stops at steps under 5e-4 m and 5e-5 rad
  config.terms = CostTerms::spherical_nonground;
  config.degeneracy_threshold = 0.0;
  const Eigen::Isometry3d start = Eigen::Translation3d(0.1, 0.0, 0.0) * Eigen::AngleAxisd(0.01, Eigen::Vector3d::UnitX());
  return registerScan(backend, start, true, config);
}

TEST(Registration, StopsWhenTheStepsStillToComeAreBelowTheTolerance) {
  // Steps of 90, 9, 0.9 mm: after the third, the steps to come (0.1 mm; 1e-5 rad) are below the
  // tolerance, one linearisation before a step itself is.
  ShrinkingSteps fast(0.1);
  const RegistrationResult fast_result = registerShrinking(fast);
  EXPECT_TRUE(fast_result.converged);
  EXPECT_EQ(fast_result.iterations, 3);
  EXPECT_EQ(fast.linearizations, 3);
  EXPECT_NEAR(fast_result.model_from_scan.translation().x(), 1e-4, 1e-9);
  EXPECT_LT(fast_result.model_from_scan.translation().norm(), 5e-4);

  // Steps shrinking by 0.6 predict more to come than the step itself: they stop on the step alone,
  // the first under 5e-4 m (0.40 mm, the tenth) and 5e-5 rad.
  ShrinkingSteps slow(0.6);
  const RegistrationResult slow_result = registerShrinking(slow);
  EXPECT_TRUE(slow_result.converged);
  EXPECT_EQ(slow_result.iterations, 10);
}

TEST(FusionWeight, FollowsTheInlierRatios) {
  RegistrationConfig config;
  NormalEquations sums;
  sums.nonground.candidates = 100;
  sums.nonground.inliers = 90;
  sums.ground.candidates = 100;
  sums.ground.inliers = 60;
  EXPECT_DOUBLE_EQ(fusionWeight(sums, config), 0.7);  // non-ground matches better: w = w1
  sums.nonground.inliers = 30;
  EXPECT_DOUBLE_EQ(fusionWeight(sums, config), 0.7 * 0.5);  // degrades with the non-ground ratio
  sums.ground.inliers = 0;
  EXPECT_DOUBLE_EQ(fusionWeight(sums, config), 1.0);  // no ground at all: non-ground alone
  config.terms = CostTerms::bev_ground;
  EXPECT_DOUBLE_EQ(fusionWeight(sums, config), 0.0);
}

// Drives down the street with turning, accelerating motion; both modes must track the truth.
class StreetDrive : public ::testing::TestWithParam<RegistrationMode> {};

TEST_P(StreetDrive, TracksTheTrueTrajectory) {
  Config config;
  config.model.mode = GetParam();
  Odometry odometry(config);
  const test::Scene scene = test::streetScene();
  Eigen::Isometry3d truth = pose(-20, 0, 0, 0, 0, 0);
  const Eigen::Isometry3d start = truth;
  double speed = 8.0;
  for (int frame = 0; frame < 25; ++frame) {
    const FrameResult result =
        odometry.process(test::scanScene(scene, config.sensor, truth, 0.1 * frame).cloud);
    ASSERT_TRUE(result.processed) << result.skip_reason;
    const Eigen::Isometry3d expected = start.inverse() * truth;
    EXPECT_LT(translationErrorMm(result.pose, expected), 20.0) << "frame " << frame;
    EXPECT_LT(rotationErrorDeg(result.pose, expected), 0.1) << "frame " << frame;
    speed += 0.3;
    truth = truth * pose(speed * 0.1, 0.0, 0.0, 0.0, 0.0, std::sin(frame * 0.3) * 0.8);
  }
}

INSTANTIATE_TEST_SUITE_P(BothModes, StreetDrive,
                         ::testing::Values(RegistrationMode::frame_to_model, RegistrationMode::frame_to_frame));

TEST(Odometry, UnusableScansAreSkippedCountedAndHarmless) {
  Odometry odometry{Config()};
  PointCloud empty;
  EXPECT_EQ(odometry.process(empty).skip_reason, "empty cloud");
  PointCloud nan_cloud;
  nan_cloud.points.assign(1000, Vec3f(NAN, NAN, NAN));
  EXPECT_EQ(odometry.process(nan_cloud).skip_reason, "too few valid points");
  const test::Scene scene = test::streetScene();
  EXPECT_TRUE(odometry.process(test::scanScene(scene, odometry.config().sensor, Eigen::Isometry3d::Identity(), 1.0).cloud).processed);
  EXPECT_EQ(odometry.process(test::scanScene(scene, odometry.config().sensor, Eigen::Isometry3d::Identity(), 1.0).cloud).skip_reason,
            "duplicate stamp");
  const FrameResult backwards =
      odometry.process(test::scanScene(scene, odometry.config().sensor, Eigen::Isometry3d::Identity(), 0.5).cloud);
  EXPECT_TRUE(backwards.processed);
  EXPECT_TRUE(backwards.reset);
  EXPECT_EQ(odometry.skippedCounts().at("empty cloud"), 1u);
  EXPECT_EQ(odometry.skippedCounts().at("too few valid points"), 1u);
  EXPECT_EQ(odometry.skippedCounts().at("duplicate stamp"), 1u);
  EXPECT_EQ(odometry.processedCount(), 2u);
}

}  // namespace
}  // namespace elo
