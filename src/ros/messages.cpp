#include "messages.hpp"

#include <sensor_msgs/PointField.h>
#include <tf2_eigen/tf2_eigen.h>

#include <Eigen/Cholesky>
#include <cstring>

#include "cloud_conversion.hpp"
#include "elo/se3.hpp"

namespace elo_ros {
namespace {

// A PointCloud2 of packed float32 fields: x y z, and normal_x normal_y normal_z when `with_normals`.
class VertexCloud {
 public:
  VertexCloud(const std_msgs::Header& header, bool with_normals) : with_normals_(with_normals) {
    message_.header = header;
    message_.height = 1;
    message_.is_bigendian = elo::hostIsBigEndian();
    message_.is_dense = true;
    const char* names[] = {"x", "y", "z", "normal_x", "normal_y", "normal_z"};
    for (int i = 0; i < (with_normals ? 6 : 3); ++i) addField(message_, names[i], sensor_msgs::PointField::FLOAT32);
  }

  void reserve(size_t points) { message_.data.reserve(points * message_.point_step); }

  void add(const elo::Vec3f& vertex, const elo::Vec3f& normal = elo::Vec3f::Zero()) {
    append(vertex);
    if (with_normals_) append(normal);
  }

  sensor_msgs::PointCloud2 finish() {
    message_.width = static_cast<uint32_t>(message_.data.size() / message_.point_step);
    message_.row_step = message_.point_step * message_.width;
    return std::move(message_);
  }

 private:
  void append(const elo::Vec3f& vector) {
    const auto* bytes = reinterpret_cast<const uint8_t*>(vector.data());
    message_.data.insert(message_.data.end(), bytes, bytes + 3 * sizeof(float));
  }

  bool with_normals_;
  sensor_msgs::PointCloud2 message_;
};

// The adjoint of a transform in twist order (translation, rotation): moves a twist (or a covariance,
// as Ad * C * Ad^T) from the transform's child frame into its parent frame.
elo::Matrix6d adjoint(const Eigen::Isometry3d& transform) {
  elo::Matrix6d result = elo::Matrix6d::Zero();
  const Eigen::Matrix3d rotation = transform.linear();
  result.topLeftCorner<3, 3>() = rotation;
  result.topRightCorner<3, 3>() = elo::skew(transform.translation()) * rotation;
  result.bottomRightCorner<3, 3>() = rotation;
  return result;
}

void copyCovariance(const std::optional<elo::Matrix6d>& covariance, boost::array<double, 36>& target) {
  target.fill(0.0);
  if (!covariance) {
    target[0] = -1.0;
    return;
  }
  Eigen::Map<Eigen::Matrix<double, 6, 6, Eigen::RowMajor>>(target.data()) = *covariance;
}

}  // namespace

sensor_msgs::PointCloud2 nonGroundModelCloud(const elo::SphericalImage& model, const std_msgs::Header& header) {
  VertexCloud cloud(header, true);
  cloud.reserve(model.pixelCount());
  for (size_t pixel = 0; pixel < model.pixelCount(); ++pixel) {
    if (model.occupied(pixel)) cloud.add(model.vertex[pixel], model.normal[pixel]);
  }
  return cloud.finish();
}

sensor_msgs::PointCloud2 groundModelCloud(const elo::BevImage& model, const std_msgs::Header& header) {
  VertexCloud cloud(header, false);
  cloud.reserve(model.size());
  for (const elo::Vec3f& vertex : model.vertex) cloud.add(vertex);
  return cloud.finish();
}

sensor_msgs::PointCloud2 labelledScanCloud(const elo::ScanImage& scan, elo::PixelLabel label,
                                           const std_msgs::Header& header) {
  const bool with_normals = label == elo::PixelLabel::nonground;
  VertexCloud cloud(header, with_normals);
  const elo::SphericalImage& image = scan.image;
  for (size_t pixel = 0; pixel < image.pixelCount(); ++pixel) {
    if (scan.label[pixel] == label) cloud.add(image.vertex[pixel], image.normal[pixel]);
  }
  return cloud.finish();
}

sensor_msgs::PointCloud2 mapCloud(const elo::MapCloud& map, size_t max_points, const std_msgs::Header& header) {
  const size_t stride = max_points > 0 && map.size() > max_points ? (map.size() + max_points - 1) / max_points : 1;
  const size_t count = (map.size() + stride - 1) / stride;
  sensor_msgs::PointCloud2 message;
  message.header = header;
  message.height = 1;
  message.width = static_cast<uint32_t>(count);
  message.is_bigendian = elo::hostIsBigEndian();
  message.is_dense = true;
  for (const char* name : {"x", "y", "z", "intensity"}) addField(message, name, sensor_msgs::PointField::FLOAT32);
  message.row_step = message.point_step * message.width;
  message.data.resize(message.row_step);
  for (size_t n = 0; n < count; ++n) {
    const size_t i = n * stride;
    const float values[4] = {map.points[i].x(), map.points[i].y(), map.points[i].z(),
                             i < map.intensity.size() ? map.intensity[i] : 0.0f};
    std::memcpy(message.data.data() + n * message.point_step, values, sizeof(values));
  }
  return message;
}

elo::PointCloud modelPoints(const elo::Model& model, const Eigen::Isometry3d& transform) {
  const Eigen::Isometry3f moved = transform.cast<float>();
  elo::PointCloud cloud;
  for (size_t pixel = 0; pixel < model.nonground.pixelCount(); ++pixel) {
    if (model.nonground.occupied(pixel)) cloud.points.push_back(moved * model.nonground.vertex[pixel]);
  }
  for (const elo::Vec3f& vertex : model.ground.vertex) cloud.points.push_back(moved * vertex);
  return cloud;
}

// Along a degenerate direction the estimate is the motion prior's, which nothing in the scan checks: a
// standard deviation of 1 m per scan (for the rotation part of a direction, the angle that sweeps 1 m at
// the registration's lever arm) tells a downstream filter to take that direction from another sensor.
constexpr double kDegeneratePriorStddev = 1.0;  // m

std::optional<elo::Matrix6d> registrationCovariance(const elo::RegistrationResult& registration) {
  const elo::TermSums& nonground = registration.last.nonground;
  const elo::TermSums& ground = registration.last.ground;
  const int inliers = nonground.inliers + ground.inliers;
  if (registration.failed || inliers == 0) return std::nullopt;
  // The residual variance under the same weighting as the fused Hessian (Eq. 1).
  const double w = registration.weight;
  double variance = 0.0;
  if (nonground.inliers > 0) variance += w * nonground.squared_error / nonground.inliers;
  if (ground.inliers > 0) variance += (1.0 - w) * ground.squared_error / ground.inliers;
  if (registration.degeneracy.any()) {
    const elo::Matrix6d covariance = registration.degeneracy.covariance(
        registration.hessian, variance / inliers, kDegeneratePriorStddev * kDegeneratePriorStddev);
    if (!covariance.allFinite()) return std::nullopt;
    return covariance;
  }
  // Cholesky, unlike LDLT, fails on a semi-definite Hessian: a direction the scan does not constrain
  // (and the registration did not report) has no finite covariance.
  const Eigen::LLT<elo::Matrix6d> solver(registration.hessian);
  if (solver.info() != Eigen::Success) return std::nullopt;
  // Column by column: a matrix right-hand side takes Eigen's blocked GEMM path, meant for large matrices.
  elo::Matrix6d inverse;
  for (int column = 0; column < 6; ++column) inverse.col(column) = solver.solve(elo::Matrix6d::Identity().col(column));
  if (!inverse.allFinite()) return std::nullopt;
  return elo::Matrix6d(variance / inliers * inverse);
}

Eigen::Isometry3d FrameBinding::childPose(const Eigen::Isometry3d& sensor_pose) const {
  return base_from_sensor * sensor_pose * base_from_sensor.inverse();
}

Eigen::Isometry3d FrameBinding::sensorPose(const Eigen::Isometry3d& sensor_pose) const {
  return base_from_sensor * sensor_pose;
}

nav_msgs::Odometry odometryMessage(const elo::FrameResult& result, double dt, const FrameBinding& frames,
                                   const ros::Time& stamp) {
  nav_msgs::Odometry odometry;
  odometry.header.stamp = stamp;
  odometry.header.frame_id = frames.odom_frame;
  odometry.child_frame_id = frames.child_frame;
  odometry.pose.pose = tf2::toMsg(frames.childPose(result.pose));
  if (dt <= 0.0) {
    // The first scan of a trajectory: the origin by definition, and no motion yet to tell a velocity.
    copyCovariance(elo::Matrix6d::Zero(), odometry.pose.covariance);
    copyCovariance(std::nullopt, odometry.twist.covariance);
    return odometry;
  }
  odometry.twist.twist = tf2::toMsg(elo::Vector6d(elo::logSE3(frames.childPose(result.delta)) / dt));

  // The registration's covariance is about this scan's motion, in the sensor frame; the adjoint of the
  // extrinsic moves it to the child frame. It is the uncertainty this scan adds to the pose: odometry
  // has no absolute reference, so the pose covariance is the per-scan (differential) one.
  // A refused registration (docs/robustness.md#a-lost-track) left the motion to the prior: unknown (-1).
  std::optional<elo::Matrix6d> motion_covariance =
      result.refusal.empty() ? registrationCovariance(result.registration) : std::nullopt;
  if (motion_covariance) {
    const elo::Matrix6d ad = adjoint(frames.base_from_sensor);
    motion_covariance = ad * *motion_covariance * ad.transpose();
  }
  copyCovariance(motion_covariance, odometry.pose.covariance);
  if (motion_covariance) *motion_covariance /= dt * dt;  // the twist is the motion divided by dt
  copyCovariance(motion_covariance, odometry.twist.covariance);
  return odometry;
}

geometry_msgs::TransformStamped odometryTransform(const nav_msgs::Odometry& odometry) {
  geometry_msgs::TransformStamped transform;
  transform.header = odometry.header;
  transform.child_frame_id = odometry.child_frame_id;
  transform.transform.translation.x = odometry.pose.pose.position.x;
  transform.transform.translation.y = odometry.pose.pose.position.y;
  transform.transform.translation.z = odometry.pose.pose.position.z;
  transform.transform.rotation = odometry.pose.pose.orientation;
  return transform;
}

}  // namespace elo_ros
