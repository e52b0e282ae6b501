// elo_odometry/OdometryNodelet: PointCloud2 (and, with imu.enabled, sensor_msgs/Imu) in; odometry, TF, path, the fused models, the drive's map and,
// with a saved map, the localization out. A shell over elo::DriveSession (docs/architecture.md): it
// converts messages, binds frames and publishes; the core does the rest.
#pragma once

#include <diagnostic_updater/diagnostic_updater.h>
#include <nodelet/nodelet.h>
#include <ros/ros.h>
#include <tf2_ros/buffer.h>
#include <tf2_ros/transform_listener.h>

#include <memory>
#include <optional>
#include <thread>

#include "diagnostics.hpp"
#include "elo/drive_session.hpp"
#include "imu_input.hpp"
#include "localization_face.hpp"
#include "messages.hpp"
#include "node_services.hpp"
#include "parameters.hpp"
#include "scan_publisher.hpp"
#include "scan_queue.hpp"
#include "step_log.hpp"

namespace elo_ros {

class OdometryNodelet : public nodelet::Nodelet {
 public:
  // Finishes the queued scans, then writes the trajectory when ~save_trajectory_on_shutdown is set.
  ~OdometryNodelet() override;

 private:
  void onInit() override;
  // The drive's map, published from its thread, and the localization when ~localization_map is set.
  void startSession(const elo::Config& config);
  void startDiagnostics();

  void onCloud(const sensor_msgs::PointCloud2ConstPtr& message);
  void runWorker();
  void processCloud(const QueuedCloud& queued);
  void reject(const std::string& reason, const std::string& detail);
  // Looks up the sensor -> base extrinsic for the first cloud's frame; false (and the cloud rejected)
  // while it is unknown, or when a cloud arrives in another frame.
  bool bindFrames(const std::string& sensor_frame);
  // On the map's thread: the thinned map on `map`, every ~map_publish_period seconds of scan time.
  void publishMap(const elo::DriveMap& map, const elo::MapScan& scan);

  NodeSettings settings_;
  std::unique_ptr<ScanQueue> queue_;
  std::thread worker_;
  PipelineStatistics statistics_;

  // The odometry and everything that follows its trajectory; the worker and the services share it.
  std::unique_ptr<elo::DriveSession> session_;
  std::optional<FrameBinding> frames_;  // set under the session's lock
  std::optional<double> last_map_stamp_;  // of the last `map` message; the map's thread's only
  // The localization mode (~localization_map): the scan the odometry processed, localized in a saved map.
  std::unique_ptr<LocalizationFace> localization_;
  std::unique_ptr<ScanPublisher> publisher_;
  std::unique_ptr<StepLog> step_log_;
  std::unique_ptr<NodeServices> services_;
  std::unique_ptr<ImuInput> imu_;  // with imu.enabled

  std::unique_ptr<tf2_ros::Buffer> tf_buffer_;
  std::unique_ptr<tf2_ros::TransformListener> tf_listener_;
  std::unique_ptr<diagnostic_updater::Updater> diagnostics_;
  ros::WallTimer diagnostics_timer_;
  ros::Subscriber cloud_subscriber_;
  ros::Publisher map_publisher_;
};

}  // namespace elo_ros
