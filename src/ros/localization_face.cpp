#include "localization_face.hpp"

#include <tf2_eigen/tf2_eigen.h>

#include <cmath>
#include <stdexcept>

#include "elo/io/map_pcd.hpp"

namespace elo_ros {
namespace {

// The map rviz is shown, thinned: a few million points of a city map would stall it.
constexpr size_t kMapDisplayPoints = 500000;

std::shared_ptr<const elo::MapCloud> loadMap(const std::string& path, const elo::Config& config) {
  const elo::PreparedMap map = elo::readPreparedMap(path, config.localization.normal_radius);
  ROS_INFO("localization map %s: %zu points%s, %zu non-finite points dropped", path.c_str(), map.cloud->size(),
           map.preparation.estimated ? ", normals estimated" : "", map.preparation.non_finite_dropped);
  return map.cloud;
}

// ROS order (x y z, rotation about x y z) is the core's twist order.
geometry_msgs::PoseWithCovarianceStamped poseMessage(const Eigen::Isometry3d& pose, const elo::Matrix6d& covariance,
                                                     const std::string& frame, const ros::Time& stamp) {
  geometry_msgs::PoseWithCovarianceStamped message;
  message.header.stamp = stamp;
  message.header.frame_id = frame;
  message.pose.pose = tf2::toMsg(pose);
  for (int row = 0; row < 6; ++row) {
    for (int col = 0; col < 6; ++col) message.pose.covariance[row * 6 + col] = covariance(row, col);
  }
  return message;
}

}  // namespace

LocalizationSettings readLocalizationSettings(const ros::NodeHandle& private_node) {
  LocalizationSettings settings;
  private_node.getParam("localization_map", settings.map_file);
  private_node.getParam("map_frame", settings.map_frame);
  if (private_node.hasParam("initial_pose") && !private_node.getParam("initial_pose", settings.initial_pose)) {
    throw std::invalid_argument("~initial_pose must be a list [x, y, z, yaw_deg]");
  }
  if (!settings.initial_pose.empty() && settings.initial_pose.size() != 4) {
    throw std::invalid_argument("~initial_pose must be a list [x, y, z, yaw_deg]");
  }
  if (settings.map_frame.empty()) throw std::invalid_argument("~map_frame must not be empty");
  return settings;
}

LocalizationFace::LocalizationFace(ros::NodeHandle& node, ros::NodeHandle& private_node,
                                   const LocalizationSettings& settings, elo::DriveSession& session)
    : settings_(settings), session_(session) {
  const std::shared_ptr<const elo::MapCloud> map = loadMap(settings.map_file, session.config());
  std::optional<Eigen::Isometry3d> initial_pose;
  if (!settings.initial_pose.empty()) initial_pose = elo::poseFromXyzYaw(settings.initial_pose);
  session.localizeIn(map, initial_pose);
  pose_publisher_ = node.advertise<geometry_msgs::PoseWithCovarianceStamped>("localization/pose", 10);
  map_publisher_ = node.advertise<sensor_msgs::PointCloud2>("localization/map", 1, true);
  std_msgs::Header header;
  header.frame_id = settings.map_frame;
  header.stamp = ros::Time::now();
  map_publisher_.publish(mapCloud(*map, kMapDisplayPoints, header));
  initial_pose_subscriber_ = node.subscribe("/initialpose", 1, &LocalizationFace::onInitialPose, this);
  relocalize_service_ = private_node.advertiseService("relocalize", &LocalizationFace::onRelocalize, this);
}

LocalizationFace::Messages LocalizationFace::update(const elo::DriveStep& step, const FrameBinding& frames,
                                                    const ros::Time& stamp) {
  std::unique_lock<std::mutex> lock(report_mutex_);
  frames_ = frames;
  if (!step.localization) {
    ROS_ERROR_THROTTLE(5.0, "localization failed on this scan, which keeps the odometry's pose: %s",
                       step.localization_failure.c_str());
    ++failed_scans_;
    last_failure_ = step.localization_failure;
    return {};
  }
  const elo::LocalizationResult& localized = *step.localization;
  last_ = localized;
  last_failure_.clear();
  ++scans_;
  lock.unlock();
  if (!localized.refusal.empty()) ROS_WARN_THROTTLE(5.0, "localization: match refused: %s", localized.refusal.c_str());
  Messages messages;
  if (localized.state == elo::LocalizationState::waiting_for_pose) return messages;
  // The core's frames: its odom is the sensor at the first scan; ROS's odom is the child frame there.
  const Eigen::Isometry3d map_from_sensor = localized.pose;
  const Eigen::Isometry3d odom_from_sensor = frames.sensorPose(step.odometry.pose);
  geometry_msgs::TransformStamped transform = tf2::eigenToTransform(map_from_sensor * odom_from_sensor.inverse());
  transform.header.stamp = stamp;
  transform.header.frame_id = settings_.map_frame;
  transform.child_frame_id = frames.odom_frame;
  messages.map_to_odom = transform;
  const Eigen::Isometry3d map_from_child = map_from_sensor * frames.base_from_sensor.inverse();
  messages.pose = poseMessage(map_from_child, localized.covariance, settings_.map_frame, stamp);
  return messages;
}

void LocalizationFace::publish(const Messages& messages) {
  if (messages.map_to_odom) tf_broadcaster_.sendTransform(*messages.map_to_odom);
  if (messages.pose) pose_publisher_.publish(*messages.pose);
}

// rviz's 2D Pose Estimate: the child frame's x, y and yaw in the map; its height comes from the map's ground.
void LocalizationFace::onInitialPose(const geometry_msgs::PoseWithCovarianceStampedConstPtr& message) {
  if (!message->header.frame_id.empty() && message->header.frame_id != settings_.map_frame) {
    ROS_WARN("/initialpose in frame '%s' ignored: localization expects '%s'", message->header.frame_id.c_str(),
             settings_.map_frame.c_str());
    return;
  }
  Eigen::Isometry3d map_from_child;
  tf2::fromMsg(message->pose.pose, map_from_child);
  Eigen::Isometry3d base_from_sensor = Eigen::Isometry3d::Identity();
  {
    std::lock_guard<std::mutex> lock(report_mutex_);
    if (frames_) base_from_sensor = frames_->base_from_sensor;
  }
  Eigen::Isometry3d hint = map_from_child * base_from_sensor;
  const double yaw = std::atan2(hint.rotation()(1, 0), hint.rotation()(0, 0));
  hint = Eigen::Translation3d(hint.translation().x(), hint.translation().y(), NAN) *
         Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitZ());
  session_.setInitialPose(hint);
  ROS_INFO("localization: initial pose x %.2f y %.2f yaw %.1f deg from /initialpose; the next scan searches around it",
           hint.translation().x(), hint.translation().y(), yaw * 180.0 / M_PI);
}

bool LocalizationFace::onRelocalize(std_srvs::Trigger::Request&, std_srvs::Trigger::Response& response) {
  switch (session_.relocalize()) {
    case elo::DriveSession::Relocalization::around_carried_hint:
      response.success = true;
      response.message = "the next scan searches around the pose given (or, lost, the last match's), as the "
                         "odometry carries it";
      break;
    case elo::DriveSession::Relocalization::no_pose_yet:
      response.success = false;
      response.message = "no pose in the map yet: give one (~initial_pose or /initialpose)";
      break;
    case elo::DriveSession::Relocalization::around_current_pose:
      response.success = true;
      response.message = "the next scan searches around the current pose in the map";
      break;
  }
  return true;
}

void LocalizationFace::report(diagnostic_updater::DiagnosticStatusWrapper& status) {
  std::lock_guard<std::mutex> lock(report_mutex_);
  using diagnostic_msgs::DiagnosticStatus;
  switch (last_.state) {
    case elo::LocalizationState::tracking:
      status.summary(DiagnosticStatus::OK, "tracking");
      break;
    case elo::LocalizationState::waiting_for_pose:
      status.summary(DiagnosticStatus::WARN, last_.hint_carried
                                                 ? "waiting: the pose given was refused (see last refusal); searched "
                                                   "around again as the vehicle moves, or give another"
                                                 : "waiting for an initial pose (/initialpose or ~initial_pose)");
      break;
    case elo::LocalizationState::lost:
      status.summary(DiagnosticStatus::ERROR, "lost: map matches refused; give a pose (/initialpose)");
      break;
  }
  if (!last_failure_.empty()) status.summary(DiagnosticStatus::ERROR, "failing: " + last_failure_);
  status.add("map", settings_.map_file);
  status.add("scans localized", scans_);
  status.add("scans failed", failed_scans_);
  status.add("inlier share", last_.health.inlier_share);
  status.add("point-to-plane RMS (m)", last_.health.rms);
  status.add("scans since the last accepted match", last_.scans_since_match);
  status.add("last refusal", last_.refusal);
  status.add("localization time (ms)", last_.milliseconds);
}

}  // namespace elo_ros
