#include "scan_publisher.hpp"

namespace elo_ros {

ScanPublisher::ScanPublisher(ros::NodeHandle& node, const NodeSettings& settings) : settings_(settings) {
  odometry_publisher_ = node.advertise<nav_msgs::Odometry>("odom", 100);
  path_publisher_ = node.advertise<nav_msgs::Path>("path", 1);
  model_nonground_publisher_ = node.advertise<sensor_msgs::PointCloud2>("model/nonground", 1);
  model_ground_publisher_ = node.advertise<sensor_msgs::PointCloud2>("model/ground", 1);
  scan_ground_publisher_ = node.advertise<sensor_msgs::PointCloud2>("scan/ground", 1);
  scan_nonground_publisher_ = node.advertise<sensor_msgs::PointCloud2>("scan/nonground", 1);
}

ScanPublisher::Messages ScanPublisher::build(const elo::DriveStep& step, elo::Odometry& odometry,
                                             const FrameBinding& frames, const std_msgs::Header& header) {
  Messages messages;
  messages.odometry = odometryMessage(step.odometry, step.since_last_processed, frames, header.stamp);
  messages.path = path(messages.odometry);
  // The models are large; they go out at most model_publish_rate times per second of scan time.
  const double stamp = header.stamp.toSec();
  const bool models_wanted =
      model_nonground_publisher_.getNumSubscribers() > 0 || model_ground_publisher_.getNumSubscribers() > 0;
  if (settings_.model_publish_rate > 0.0 && models_wanted && stamp >= next_model_stamp_) {
    next_model_stamp_ = stamp + 1.0 / settings_.model_publish_rate;
    // In the sensor frame at the scan's reference instant, as are the labelled scans below: mid-sweep for
    // per-point times from the cloud, a fraction of the sweep's motion from the stamp (docs/deskew.md).
    const elo::Model& model = odometry.backend().model();
    messages.model_nonground = nonGroundModelCloud(model.nonground, header);
    messages.model_ground = groundModelCloud(model.ground, header);
  }
  if (scan_ground_publisher_.getNumSubscribers() > 0) {
    messages.scan_ground = labelledScanCloud(odometry.backend().scan(), elo::PixelLabel::ground, header);
  }
  if (scan_nonground_publisher_.getNumSubscribers() > 0) {
    messages.scan_nonground = labelledScanCloud(odometry.backend().scan(), elo::PixelLabel::nonground, header);
  }
  return messages;
}

// Every pose goes on the path; the message is built only when someone listens.
std::optional<nav_msgs::Path> ScanPublisher::path(const nav_msgs::Odometry& odometry) {
  geometry_msgs::PoseStamped pose;
  pose.header = odometry.header;
  pose.pose = odometry.pose.pose;
  path_.push_back(pose);
  if (settings_.path_length > 0 && path_.size() > static_cast<size_t>(settings_.path_length)) path_.pop_front();
  if (path_publisher_.getNumSubscribers() == 0) return std::nullopt;
  nav_msgs::Path path;
  path.header = odometry.header;
  path.poses.assign(path_.begin(), path_.end());
  return path;
}

void ScanPublisher::restart() {
  path_.clear();
  next_model_stamp_ = -std::numeric_limits<double>::infinity();
}

void ScanPublisher::publish(const Messages& messages) {
  odometry_publisher_.publish(messages.odometry);
  if (settings_.publish_tf) tf_broadcaster_.sendTransform(odometryTransform(messages.odometry));
  if (messages.path) path_publisher_.publish(*messages.path);
  if (messages.model_nonground) model_nonground_publisher_.publish(*messages.model_nonground);
  if (messages.model_ground) model_ground_publisher_.publish(*messages.model_ground);
  if (messages.scan_ground) scan_ground_publisher_.publish(*messages.scan_ground);
  if (messages.scan_nonground) scan_nonground_publisher_.publish(*messages.scan_nonground);
}

}  // namespace elo_ros
