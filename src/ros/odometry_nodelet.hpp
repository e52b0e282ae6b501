// elo_odometry/OdometryNodelet: PointCloud2 in; odometry, TF, path and the fused models out. A thin
// shell around elo::Odometry: it converts messages, binds frames and publishes; the core does the rest.
#pragma once

#include <diagnostic_updater/diagnostic_updater.h>
#include <geometry_msgs/PoseStamped.h>
#include <nav_msgs/Path.h>
#include <nodelet/nodelet.h>
#include <ros/ros.h>
#include <std_srvs/Trigger.h>
#include <tf2_ros/buffer.h>
#include <tf2_ros/transform_broadcaster.h>
#include <tf2_ros/transform_listener.h>

#include <deque>
#include <limits>
#include <memory>
#include <mutex>
#include <optional>
#include <thread>
#include <vector>

#include "diagnostics.hpp"
#include "elo/map_builder.hpp"
#include "elo/odometry.hpp"
#include "localization_face.hpp"
#include "messages.hpp"
#include "parameters.hpp"
#include "scan_queue.hpp"

namespace elo_ros {

class OdometryNodelet : public nodelet::Nodelet {
 public:
  // Finishes the queued scans, then writes the trajectory when ~save_trajectory_on_shutdown is set.
  ~OdometryNodelet() override;

 private:
  // The messages of one processed scan, built under the odometry lock and published after it.
  struct ScanMessages {
    nav_msgs::Odometry odometry;
    std::optional<nav_msgs::Path> path;
    std::optional<sensor_msgs::PointCloud2> model_nonground, model_ground, scan_ground, scan_nonground;
    std::optional<LocalizationFace::Messages> localization;
  };

  void onInit() override;
  elo::Config loadConfig();
  void advertise();

  void onCloud(const sensor_msgs::PointCloud2ConstPtr& message);
  void runWorker();
  void processCloud(const QueuedCloud& queued);
  void reject(const std::string& reason, const std::string& detail);
  // Looks up the sensor -> base extrinsic for the first cloud's frame; false (and the cloud rejected)
  // while it is unknown, or when a cloud arrives in another frame.
  bool bindFrames(const std::string& sensor_frame);
  // Warns and counts when the odometry restarted at this scan; a reset also forgets the trajectory.
  void reportRestart(const elo::FrameResult& result, double stamp);
  ScanMessages buildMessages(const elo::FrameResult& result, double dt, const std_msgs::Header& header);
  void publish(const ScanMessages& messages);
  void forgetTrajectory();

  bool onReset(std_srvs::Trigger::Request& request, std_srvs::Trigger::Response& response);
  bool onSaveTrajectory(std_srvs::Trigger::Request& request, std_srvs::Trigger::Response& response);
  bool onSaveMap(std_srvs::Trigger::Request& request, std_srvs::Trigger::Response& response);
  bool onSaveModel(std_srvs::Trigger::Request& request, std_srvs::Trigger::Response& response);
  // Copies the processed scan's points for the drive's map, placed by `sensor_pose` (the odom frame);
  // after the scan's messages are out, so that the map never delays a pose.
  // `generation`: map_generation_ when the scan was processed; a scan from before a reset is left out.
  // Says when a registration was refused, the track recovered or the sensor height does not fit.
  void logTrackingHealth(const elo::FrameResult& result);
  // Says where the start search put a start in motion: a warning when the scans could not tell.
  void logStartSearch(const elo::StartSearchResult& search);
  void feedMap(const elo::FrameResult& result, const elo::PointCloud& cloud, const Eigen::Isometry3d& sensor_pose,
               size_t generation);
  // On the map's thread: the thinned map on `map`, every ~map_publish_period seconds of scan time.
  void publishMap(const elo::DriveMap& map, const elo::MapScan& scan);
  std::string saveTrajectory(const OutputFiles& files);  // returns what it wrote; throws on failure

  NodeSettings settings_;
  std::unique_ptr<ScanQueue> queue_;
  std::thread worker_;
  PipelineStatistics statistics_;

  // The odometry and everything that follows its trajectory; the worker and the services share them.
  std::mutex odometry_mutex_;
  std::unique_ptr<elo::Odometry> odometry_;
  std::optional<FrameBinding> frames_;
  std::optional<double> last_processed_stamp_;
  double next_model_stamp_ = -std::numeric_limits<double>::infinity();  // scan time of the next models
  std::vector<double> trajectory_stamps_;
  std::vector<Eigen::Isometry3d> trajectory_poses_;  // the sensor's, as elo_run writes them
  std::deque<geometry_msgs::PoseStamped> path_;
  // The drive's map (docs/map.md) on a thread of its own; null with ~build_map false.
  std::unique_ptr<elo::MapBuilder> map_;
  size_t map_generation_ = 0;  // counts the resets that cleared the map
  std::optional<double> last_map_stamp_;  // of the last `map` message; the map's thread's only
  // The localization mode (~localization_map): the scan the odometry processed, localized in a saved map.
  std::unique_ptr<LocalizationFace> localization_;

  std::unique_ptr<tf2_ros::Buffer> tf_buffer_;
  std::unique_ptr<tf2_ros::TransformListener> tf_listener_;
  std::unique_ptr<tf2_ros::TransformBroadcaster> tf_broadcaster_;
  std::unique_ptr<diagnostic_updater::Updater> diagnostics_;
  ros::WallTimer diagnostics_timer_;
  ros::Subscriber cloud_subscriber_;
  ros::Publisher odometry_publisher_, path_publisher_;
  ros::Publisher model_nonground_publisher_, model_ground_publisher_;
  ros::Publisher scan_ground_publisher_, scan_nonground_publisher_, map_publisher_;
  ros::ServiceServer reset_service_, save_trajectory_service_, save_map_service_, save_model_service_;
};

}  // namespace elo_ros
