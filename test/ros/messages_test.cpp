// The core's results as messages: model and scan clouds, covariance, REP-105 frames. No ROS master.
#include <gtest/gtest.h>
#include <tf2_eigen/tf2_eigen.h>

#include <cstring>

#include "elo/se3.hpp"
#include "messages.hpp"

namespace {

std::vector<float> floatsOf(const sensor_msgs::PointCloud2& cloud) {
  std::vector<float> values(cloud.data.size() / sizeof(float));
  std::memcpy(values.data(), cloud.data.data(), cloud.data.size());
  return values;
}

std::vector<std::string> fieldNames(const sensor_msgs::PointCloud2& cloud) {
  std::vector<std::string> names;
  for (const auto& field : cloud.fields) names.push_back(field.name);
  return names;
}

// Largest entry-wise difference: Eigen's isApprox on these sizes trips a GCC 12 false warning with AVX-512.
template <typename A, typename B>
double largestDifference(const A& a, const B& b) {
  return (a.matrix() - b.matrix()).cwiseAbs().maxCoeff();
}

std_msgs::Header header() {
  std_msgs::Header h;
  h.stamp = ros::Time(12, 5);
  h.frame_id = "velodyne";
  return h;
}

TEST(RosMessages, NonGroundModelCarriesNormalsOfOccupiedPixels) {
  elo::SphericalImage model;
  model.resize(2, 2);
  model.vertex[1] = {1, 2, 3};
  model.normal[1] = {0, 0, 1};
  model.range[1] = 3.7f;
  model.vertex[2] = {4, 5, 6};
  model.range[2] = 8.8f;  // no normal

  const sensor_msgs::PointCloud2 cloud = elo_ros::nonGroundModelCloud(model, header());
  EXPECT_EQ(fieldNames(cloud), (std::vector<std::string>{"x", "y", "z", "normal_x", "normal_y", "normal_z"}));
  EXPECT_EQ(cloud.width * cloud.height, 2u);
  EXPECT_EQ(cloud.point_step, 24u);
  EXPECT_EQ(cloud.row_step, 48u);
  EXPECT_EQ(floatsOf(cloud), (std::vector<float>{1, 2, 3, 0, 0, 1, 4, 5, 6, 0, 0, 0}));
  EXPECT_EQ(cloud.header.frame_id, "velodyne");
  EXPECT_EQ(cloud.header.stamp, ros::Time(12, 5));
}

TEST(RosMessages, GroundModelHoldsEveryBevPoint) {
  elo::BevImage model;
  model.resize(4, 4);
  model.keepCloser(3, {1, 0, -1.7f}, 0.0f);
  model.keepCloser(9, {2, 1, -1.7f}, 0.0f);
  const sensor_msgs::PointCloud2 cloud = elo_ros::groundModelCloud(model, header());
  EXPECT_EQ(fieldNames(cloud), (std::vector<std::string>{"x", "y", "z"}));
  EXPECT_EQ(floatsOf(cloud), (std::vector<float>{1, 0, -1.7f, 2, 1, -1.7f}));
}

TEST(RosMessages, LabelledScanSelectsOneLabel) {
  elo::ScanImage scan;
  scan.resize(1, 3);
  scan.image.vertex = {{1, 1, 1}, {2, 2, 2}, {3, 3, 3}};
  scan.image.normal = {{1, 0, 0}, {0, 0, 0}, {0, 1, 0}};
  scan.label = {elo::PixelLabel::nonground, elo::PixelLabel::ground, elo::PixelLabel::empty};
  EXPECT_EQ(floatsOf(elo_ros::labelledScanCloud(scan, elo::PixelLabel::nonground, header())),
            (std::vector<float>{1, 1, 1, 1, 0, 0}));
  EXPECT_EQ(floatsOf(elo_ros::labelledScanCloud(scan, elo::PixelLabel::ground, header())),
            (std::vector<float>{2, 2, 2}));
}

TEST(RosMessages, ModelPointsMoveIntoTheOdomFrame) {
  elo::Model model;
  model.nonground.resize(1, 1);
  model.nonground.vertex[0] = {1, 0, 0};
  model.nonground.range[0] = 1.0f;
  model.ground.resize(2, 2);
  model.ground.keepCloser(0, {0, 1, 0}, 0.0f);
  const Eigen::Isometry3d moved(Eigen::Translation3d(10, 0, 0) * Eigen::AngleAxisd(M_PI / 2, Eigen::Vector3d::UnitZ()));
  const elo::PointCloud points = elo_ros::modelPoints(model, moved);
  ASSERT_EQ(points.size(), 2u);
  EXPECT_LT(largestDifference(points.points[0], elo::Vec3f(10, 1, 0)), 1e-5);
  EXPECT_LT(largestDifference(points.points[1], elo::Vec3f(9, 0, 0)), 1e-5);
}

elo::RegistrationResult registration(double nonground_error, double ground_error) {
  elo::RegistrationResult result;
  result.hessian = (elo::Vector6d() << 1, 2, 4, 8, 16, 32).finished().asDiagonal();
  result.weight = 0.5;
  result.last.nonground.inliers = 300;
  result.last.nonground.squared_error = nonground_error;
  result.last.ground.inliers = 100;
  result.last.ground.squared_error = ground_error;
  return result;
}

TEST(RosMessages, CovarianceIsTheScaledInverseHessian) {
  // Residual variance 0.5 * 3/300 + 0.5 * 2/100 = 0.015, over 400 inliers.
  const auto covariance = elo_ros::registrationCovariance(registration(3.0, 2.0));
  ASSERT_TRUE(covariance.has_value());
  const elo::Vector6d inverse_diagonal = (elo::Vector6d() << 1, 0.5, 0.25, 0.125, 0.0625, 0.03125).finished();
  const elo::Matrix6d expected = (0.015 / 400.0) * inverse_diagonal.asDiagonal().toDenseMatrix();
  EXPECT_LT(largestDifference(*covariance, expected), 1e-15) << *covariance;

  elo::RegistrationResult failed = registration(3.0, 2.0);
  failed.failed = true;
  EXPECT_FALSE(elo_ros::registrationCovariance(failed).has_value());
  elo::RegistrationResult singular = registration(3.0, 2.0);
  singular.hessian(5, 5) = 0.0;
  EXPECT_FALSE(elo_ros::registrationCovariance(singular).has_value());
}

TEST(RosMessages, DegenerateDirectionsGetTheLargeVarianceOfThePrior) {
  elo::RegistrationResult degenerate = registration(3.0, 2.0);
  degenerate.hessian(0, 0) = 0.0;  // nothing constrains x: a tunnel
  degenerate.degeneracy = *elo::analyseDegeneracy(degenerate.hessian, elo::RegistrationConfig().degeneracy_threshold);
  ASSERT_EQ(degenerate.degeneracy.count, 1);
  const auto covariance = elo_ros::registrationCovariance(degenerate);
  ASSERT_TRUE(covariance.has_value()) << "a degenerate scan still has a covariance";
  EXPECT_NEAR((*covariance)(0, 0), 1.0, 1e-12) << "(1 m)^2 along the degenerate direction";
  // The constrained directions keep the scaled inverse Hessian, with no correlation to x.
  const elo::Vector6d constrained =
      (0.015 / 400.0) * (elo::Vector6d() << 0, 0.5, 0.25, 0.125, 0.0625, 0.03125).finished();
  EXPECT_LT((covariance->diagonal().tail<5>() - constrained.tail<5>()).cwiseAbs().maxCoeff(), 1e-15);
  EXPECT_LT(covariance->row(0).tail<5>().cwiseAbs().maxCoeff(), 1e-15);
}

elo_ros::FrameBinding frames() {
  const Eigen::Isometry3d base_from_sensor(Eigen::Translation3d(0.8, 0.1, 1.73) *
                                           Eigen::AngleAxisd(0.05, Eigen::Vector3d::UnitZ()));
  return {"odom", "velodyne", "base_link", base_from_sensor};
}

TEST(RosMessages, OdomFrameIsWhereTheBaseStarted) {
  const elo_ros::FrameBinding binding = frames();
  EXPECT_LT(largestDifference(binding.childPose(Eigen::Isometry3d::Identity()), Eigen::Isometry3d::Identity()), 1e-15);
  const Eigen::Isometry3d sensor_pose(Eigen::Translation3d(5, 1, 0) * Eigen::AngleAxisd(0.3, Eigen::Vector3d::UnitZ()));
  // The TF chain odom -> base_link -> sensor reproduces the sensor's pose in the odom frame.
  EXPECT_LT(largestDifference(binding.childPose(sensor_pose) * binding.base_from_sensor, binding.sensorPose(sensor_pose)),
            1e-12);
}

TEST(RosMessages, OdometryOfTheFirstScanIsTheExactOrigin) {
  elo::FrameResult result;
  result.processed = true;
  const nav_msgs::Odometry odometry = elo_ros::odometryMessage(result, 0.0, frames(), ros::Time(3, 0));
  EXPECT_EQ(odometry.header.frame_id, "odom");
  EXPECT_EQ(odometry.child_frame_id, "base_link");
  EXPECT_EQ(odometry.header.stamp, ros::Time(3, 0));
  EXPECT_EQ(odometry.pose.pose.position.x, 0.0);
  EXPECT_EQ(odometry.pose.pose.orientation.w, 1.0);
  EXPECT_EQ(odometry.pose.covariance[0], 0.0);
  EXPECT_EQ(odometry.twist.covariance[0], -1.0) << "no velocity is known yet";
}

TEST(RosMessages, OdometryTwistAndCovarianceAreInTheChildFrame) {
  const elo_ros::FrameBinding binding = frames();
  elo::FrameResult result;
  result.processed = true;
  result.delta = Eigen::Translation3d(1.0, 0.0, 0.0) * Eigen::AngleAxisd(0.02, Eigen::Vector3d::UnitZ());
  result.pose = result.delta;
  result.registration = registration(3.0, 2.0);
  const double dt = 0.1;
  const nav_msgs::Odometry odometry = elo_ros::odometryMessage(result, dt, binding, ros::Time(3, 0));

  Eigen::Isometry3d pose;
  tf2::fromMsg(odometry.pose.pose, pose);
  EXPECT_LT(largestDifference(pose, binding.childPose(result.pose)), 1e-12);
  const elo::Vector6d expected_twist = elo::logSE3(binding.childPose(result.delta)) / dt;
  EXPECT_NEAR(odometry.twist.twist.linear.x, expected_twist[0], 1e-12);
  EXPECT_NEAR(odometry.twist.twist.linear.y, expected_twist[1], 1e-12);
  EXPECT_NEAR(odometry.twist.twist.angular.z, expected_twist[5], 1e-12);

  // A sensor rotated about z: the diagonal covariance mixes x and y, and rotation about z stays put.
  const Eigen::Map<const Eigen::Matrix<double, 6, 6, Eigen::RowMajor>> pose_covariance(odometry.pose.covariance.data());
  const Eigen::Map<const Eigen::Matrix<double, 6, 6, Eigen::RowMajor>> twist_covariance(odometry.twist.covariance.data());
  EXPECT_NE(pose_covariance(0, 1), 0.0);
  EXPECT_NEAR(pose_covariance(5, 5), elo_ros::registrationCovariance(result.registration)->coeff(5, 5), 1e-15);
  EXPECT_LT(largestDifference(pose_covariance, pose_covariance.transpose()), 1e-18);
  EXPECT_LT(largestDifference(twist_covariance, pose_covariance / (dt * dt)), 1e-15);

  elo::FrameResult refused = result;
  refused.refusal = elo::refusal::kAccelerates;  // its pose is the motion prior's
  const nav_msgs::Odometry prior = elo_ros::odometryMessage(refused, dt, binding, ros::Time(3, 0));
  EXPECT_EQ(prior.pose.covariance[0], -1.0);
  EXPECT_EQ(prior.twist.covariance[0], -1.0);

  result.registration.failed = true;
  const nav_msgs::Odometry unknown = elo_ros::odometryMessage(result, dt, binding, ros::Time(3, 0));
  EXPECT_EQ(unknown.pose.covariance[0], -1.0);
  EXPECT_EQ(unknown.twist.covariance[0], -1.0);
}

TEST(RosMessages, TransformMirrorsTheOdometry) {
  elo::FrameResult result;
  result.pose = Eigen::Translation3d(1, 2, 3) * Eigen::AngleAxisd(0.4, Eigen::Vector3d::UnitY());
  const nav_msgs::Odometry odometry = elo_ros::odometryMessage(result, 0.0, frames(), ros::Time(7, 0));
  const geometry_msgs::TransformStamped transform = elo_ros::odometryTransform(odometry);
  EXPECT_EQ(transform.header.frame_id, "odom");
  EXPECT_EQ(transform.child_frame_id, "base_link");
  EXPECT_EQ(transform.header.stamp, ros::Time(7, 0));
  EXPECT_EQ(transform.transform.translation.z, odometry.pose.pose.position.z);
  EXPECT_EQ(transform.transform.rotation.y, odometry.pose.pose.orientation.y);
}

}  // namespace
