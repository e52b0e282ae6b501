// The core's results as ROS messages: the fused models and the labelled scan as PointCloud2, the
// odometry with its covariance, and the frames the poses are published in.
#pragma once

#include <geometry_msgs/TransformStamped.h>
#include <nav_msgs/Odometry.h>
#include <sensor_msgs/PointCloud2.h>
#include <std_msgs/Header.h>

#include <Eigen/Geometry>
#include <optional>

#include "elo/map/map_cloud.hpp"
#include "elo/pipeline/odometry.hpp"
#include "elo/types.hpp"

namespace elo_ros {

// The non-ground model (fused spherical range image): x y z normal_x normal_y normal_z, float32, one
// point per occupied pixel; a pixel without a normal has normal (0, 0, 0).
sensor_msgs::PointCloud2 nonGroundModelCloud(const elo::SphericalImage& model, const std_msgs::Header& header);

// The ground model (BEV map): x y z, float32, one point per occupied cell. The BEV map stores no
// normals: the registration fits them from neighbouring cells only where a scan point associates.
sensor_msgs::PointCloud2 groundModelCloud(const elo::BevImage& model, const std_msgs::Header& header);

// The scan's pixels carrying `label`; non-ground pixels with their normals (as nonGroundModelCloud),
// ground pixels as x y z.
sensor_msgs::PointCloud2 labelledScanCloud(const elo::ScanImage& scan, elo::PixelLabel label,
                                           const std_msgs::Header& header);

// A map for display (the drive's, or a saved one localized in): x y z intensity (0 where it has none),
// float32; every point, or every n-th where the map has more than `max_points` (0: no limit).
sensor_msgs::PointCloud2 mapCloud(const elo::MapCloud& map, size_t max_points, const std_msgs::Header& header);

// The model as one point list for elo::writePcd, moved by `transform` (sensor -> odom frame).
elo::PointCloud modelPoints(const elo::Model& model, const Eigen::Isometry3d& transform);

// The covariance of one scan's registration in twist order (translation, then rotation; ROS order
// x y z roll pitch yaw for small angles), about the motion T^{t-1}_t in the sensor frame: the inverse
// of the fused, normalised Gauss-Newton Hessian times the residual variance, divided by the number of
// inliers the normalisation averaged over. Empty when the registration failed, had no inliers or its
// Hessian is not positive definite (some direction unconstrained).
std::optional<elo::Matrix6d> registrationCovariance(const elo::RegistrationResult& registration);

// Frame ids and the sensor->base extrinsic that turn the core's sensor poses into REP-105 frames.
struct FrameBinding {
  std::string odom_frame;
  std::string sensor_frame;              // the clouds' frame_id
  std::string child_frame;               // base_link, or the sensor frame itself
  Eigen::Isometry3d base_from_sensor;    // identity when the child frame is the sensor frame

  // The child frame in the odom frame, for a core pose (the sensor in the first scan's sensor frame):
  // the odom frame is where the child frame was at the first scan.
  Eigen::Isometry3d childPose(const Eigen::Isometry3d& sensor_pose) const;
  // The sensor in the odom frame.
  Eigen::Isometry3d sensorPose(const Eigen::Isometry3d& sensor_pose) const;
};

// nav_msgs/Odometry for a processed scan: the pose of the child frame in the odom frame, the twist of
// the child frame in the child frame (the scan's motion over `dt`), and covariances from the
// registration. Covariance entry 0 is -1 (unknown, as REP-105 readers expect) where there is none.
nav_msgs::Odometry odometryMessage(const elo::FrameResult& result, double dt, const FrameBinding& frames,
                                   const ros::Time& stamp);

geometry_msgs::TransformStamped odometryTransform(const nav_msgs::Odometry& odometry);

}  // namespace elo_ros
