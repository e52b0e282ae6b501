// The node's outputs of one processed scan: odometry, TF, the path, the fused models (at most
// ~model_publish_rate times per second of scan time) and the labelled scan, each built only when someone
// listens. Built under the drive session's lock (the backend still holds the scan), published after it.
#pragma once

#include <geometry_msgs/PoseStamped.h>
#include <nav_msgs/Path.h>
#include <ros/ros.h>
#include <tf2_ros/transform_broadcaster.h>

#include <deque>
#include <limits>
#include <optional>

#include "elo/drive_session.hpp"
#include "messages.hpp"
#include "parameters.hpp"

namespace elo_ros {

class ScanPublisher {
 public:
  struct Messages {
    nav_msgs::Odometry odometry;
    std::optional<nav_msgs::Path> path;
    std::optional<sensor_msgs::PointCloud2> model_nonground, model_ground, scan_ground, scan_nonground;
  };

  // Advertises odom, path, model/* and scan/*.
  ScanPublisher(ros::NodeHandle& node, const NodeSettings& settings);

  // From DriveSession::WhileCurrent, for a processed scan; `header`: its stamp and the sensor frame.
  Messages build(const elo::DriveStep& step, elo::Odometry& odometry, const FrameBinding& frames,
                 const std_msgs::Header& header);
  // The trajectory restarted (DriveStep::restarted): the path and the models' schedule start again.
  void restart();
  void publish(const Messages& messages);

 private:
  std::optional<nav_msgs::Path> path(const nav_msgs::Odometry& odometry);

  const NodeSettings& settings_;
  std::deque<geometry_msgs::PoseStamped> path_;
  double next_model_stamp_ = -std::numeric_limits<double>::infinity();  // scan time of the next models
  tf2_ros::TransformBroadcaster tf_broadcaster_;
  ros::Publisher odometry_publisher_, path_publisher_;
  ros::Publisher model_nonground_publisher_, model_ground_publisher_;
  ros::Publisher scan_ground_publisher_, scan_nonground_publisher_;
};

}  // namespace elo_ros
