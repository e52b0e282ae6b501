// The localization mode of the odometry nodelet (~localization_map set, docs/localization.md): each scan
// the odometry processed is localized in the saved map with the same backend images, by the drive session
// (its localization step), so the scan is processed once. Publishes map -> odom and localization/pose; takes the initial pose from
// ~initial_pose, rviz's 2D Pose Estimate (/initialpose) and the ~relocalize service.
#pragma once

#include <diagnostic_updater/DiagnosticStatusWrapper.h>
#include <geometry_msgs/PoseWithCovarianceStamped.h>
#include <geometry_msgs/TransformStamped.h>
#include <ros/ros.h>
#include <std_srvs/Trigger.h>
#include <tf2_ros/transform_broadcaster.h>

#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <vector>

#include "elo/drive_session.hpp"
#include "messages.hpp"

namespace elo_ros {

struct LocalizationSettings {
  std::string map_file;            // ~localization_map: empty, no localization
  std::string map_frame = "map";   // ~map_frame
  // ~initial_pose [x, y, z, yaw_deg]: the sensor in the map at the first scan (empty: wait for one).
  std::vector<double> initial_pose;
};

// Reads the settings; throws std::invalid_argument naming a parameter that cannot work.
LocalizationSettings readLocalizationSettings(const ros::NodeHandle& private_node);

class LocalizationFace {
 public:
  // The messages of one localized scan, built under the odometry lock and published after it.
  struct Messages {
    std::optional<geometry_msgs::TransformStamped> map_to_odom;  // once localized
    std::optional<geometry_msgs::PoseWithCovarianceStamped> pose;
  };

  // Loads the map and has `session` localize in it (throws IoError, std::invalid_argument or
  // std::runtime_error, as for a backend that cannot render maps).
  LocalizationFace(ros::NodeHandle& node, ros::NodeHandle& private_node, const LocalizationSettings& settings,
                   elo::DriveSession& session);

  // The messages of a processed scan's localization (DriveStep::localization). A scan the backend could
  // not render the map for (the CUDA backend: the map's part near the vehicle does not fit in the device's
  // free memory) is logged, counted in the diagnostics and left unlocalized; the odometry goes on.
  Messages update(const elo::DriveStep& step, const FrameBinding& frames, const ros::Time& stamp);
  void publish(const Messages& messages);
  // For diagnostic_updater: OK while tracking, WARN while waiting for a pose, ERROR when lost or when the
  // last scan failed.
  void report(diagnostic_updater::DiagnosticStatusWrapper& status);

 private:
  void onInitialPose(const geometry_msgs::PoseWithCovarianceStampedConstPtr& message);
  bool onRelocalize(std_srvs::Trigger::Request& request, std_srvs::Trigger::Response& response);

  LocalizationSettings settings_;
  elo::DriveSession& session_;
  std::mutex report_mutex_;  // guards what follows: the scans' thread writes it, the callbacks read it
  std::optional<FrameBinding> frames_;  // of the last localized scan, for /initialpose's base -> sensor
  elo::LocalizationResult last_;
  size_t scans_ = 0;
  size_t failed_scans_ = 0;
  std::string last_failure_;  // empty when the last scan did not fail
  tf2_ros::TransformBroadcaster tf_broadcaster_;
  ros::Publisher pose_publisher_;
  ros::Publisher map_publisher_;  // latched, once
  ros::Subscriber initial_pose_subscriber_;
  ros::ServiceServer relocalize_service_;
};

}  // namespace elo_ros
