#include "odometry_nodelet.hpp"

#include <tf2_eigen/tf2_eigen.h>

#include "cloud_conversion.hpp"
#include "elo/sensor/sensor_fit.hpp"

namespace elo_ros {
namespace {

using Clock = std::chrono::steady_clock;

constexpr double kWarningPeriod = 5.0;  // s between repeats of one throttled warning
// Scans waiting for the map's thread: a second of a 10 Hz sensor (about 15 MB for an HDL-64E). The map
// adds a scan in a few milliseconds; the queue fills only when its thread gets no CPU for a second.
constexpr size_t kMapQueue = 10;

}  // namespace

void OdometryNodelet::onInit() {
  try {
    settings_ = readNodeSettings(getPrivateNodeHandle());
    startSession(readConfig(getPrivateNodeHandle(), getName()));
  } catch (const std::exception& error) {
    NODELET_FATAL("cannot start: %s", error.what());
    throw;
  }
  const elo::Config& config = session_->config();
  if (!session_->odometry().backendWarning().empty()) NODELET_WARN("%s", session_->odometry().backendWarning().c_str());
  const std::string normal_reach = elo::normalReachWarning(config);
  if (!normal_reach.empty()) NODELET_WARN("%s", normal_reach.c_str());
  if (!settings_.publish_sensor_frame_directly) {
    tf_buffer_ = std::make_unique<tf2_ros::Buffer>();
    tf_listener_ = std::make_unique<tf2_ros::TransformListener>(*tf_buffer_, getNodeHandle());
  }
  publisher_ = std::make_unique<ScanPublisher>(getNodeHandle(), settings_);
  // Latched: rviz, started late, still shows the map.
  if (session_->driveMap()) map_publisher_ = getNodeHandle().advertise<sensor_msgs::PointCloud2>("map", 1, true);
  services_ = std::make_unique<NodeServices>(getPrivateNodeHandle(), getName(), settings_, *session_, frames_);
  try {
    const LocalizationSettings localization = readLocalizationSettings(getPrivateNodeHandle());
    if (!localization.map_file.empty()) {
      localization_ = std::make_unique<LocalizationFace>(getNodeHandle(), getPrivateNodeHandle(), localization, *session_);
    }
  } catch (const std::exception& error) {
    NODELET_FATAL("cannot start localization: %s", error.what());
    throw;
  }
  step_log_ = std::make_unique<StepLog>(getName(), config, statistics_);
  if (config.imu.enabled) imu_ = std::make_unique<ImuInput>(getNodeHandle(), settings_, *session_, getName());
  startDiagnostics();

  // 0: every scan is queued (bag replay); 1: only the latest waits, older ones are dropped and counted.
  queue_ = std::make_unique<ScanQueue>(settings_.process_every_scan ? 0 : 1);
  worker_ = std::thread([this] { runWorker(); });
  // roscpp's own queue stays unbounded when every scan counts; the callback empties it at once anyway.
  const uint32_t subscriber_queue = settings_.process_every_scan ? 0 : 5;
  cloud_subscriber_ = getNodeHandle().subscribe("points", subscriber_queue, &OdometryNodelet::onCloud, this);

  NODELET_INFO("ELO odometry on %s: sensor %s, %s backend, %d threads (0 = all), %s, %s; publishing %s -> %s",
               cloud_subscriber_.getTopic().c_str(), config.sensor.name.c_str(), session_->odometry().backend().name(),
               config.runtime.threads,
               config.model.mode == elo::RegistrationMode::frame_to_model ? "frame-to-model" : "frame-to-frame",
               settings_.process_every_scan ? "every scan processed" : "latest scan processed",
               settings_.odom_frame.c_str(),
               settings_.publish_sensor_frame_directly ? "<sensor frame>" : settings_.base_frame.c_str());
}

void OdometryNodelet::startSession(const elo::Config& config) {
  elo::DriveSessionOptions options;
  options.build_map = settings_.build_map;
  options.map_queue = kMapQueue;
  options.after_map_scan = [this](const elo::DriveMap& map, const elo::MapScan& scan) { publishMap(map, scan); };
  // A reset starts a new trajectory: the poses before it lie in another odom frame.
  options.trajectory_restarts = true;
  session_ = std::make_unique<elo::DriveSession>(config, options);
}

void OdometryNodelet::startDiagnostics() {
  diagnostics_ = std::make_unique<diagnostic_updater::Updater>(getNodeHandle(), getPrivateNodeHandle(), getName());
  diagnostics_->setHardwareID(session_->config().sensor.name);
  diagnostics_->add("odometry", &statistics_, &PipelineStatistics::report);
  if (localization_) diagnostics_->add("localization", localization_.get(), &LocalizationFace::report);
  if (imu_) diagnostics_->add("imu", &imu_->statistics(), &ImuStatistics::report);
  // A wall timer: diagnostics must keep coming while a replayed clock is paused or not yet started.
  diagnostics_timer_ = getNodeHandle().createWallTimer(ros::WallDuration(1.0),
                                                       [this](const ros::WallTimerEvent&) { diagnostics_->force_update(); });
}

OdometryNodelet::~OdometryNodelet() {
  if (!queue_) return;  // onInit failed: nothing started
  cloud_subscriber_.shutdown();
  diagnostics_timer_.stop();
  const size_t waiting = queue_->size();
  if (waiting > 0) NODELET_INFO("finishing %zu queued scans before stopping", waiting);
  queue_->close();
  worker_.join();
  if (settings_.save_trajectory_on_shutdown) services_->saveTrajectoryOnShutdown();
  diagnostics_.reset();  // it reports on imu_
  imu_.reset();          // its callbacks hand samples to the session
  session_.reset();  // its map's thread publishes through members destroyed before it
}

void OdometryNodelet::onCloud(const sensor_msgs::PointCloud2ConstPtr& message) {
  statistics_.cloudReceived();
  const size_t dropped = queue_->push({message, Clock::now()});
  if (dropped > 0) {
    statistics_.cloudsDropped(dropped);
    NODELET_WARN_THROTTLE(kWarningPeriod,
                          "processing is slower than the input: older scans dropped (set ~process_every_scan "
                          "to queue every scan instead)");
  }
}

void OdometryNodelet::runWorker() {
  while (const std::optional<QueuedCloud> queued = queue_->pop()) processCloud(*queued);
}

void OdometryNodelet::reject(const std::string& reason, const std::string& detail) {
  statistics_.cloudRejected(reason);
  NODELET_WARN_THROTTLE(kWarningPeriod, "cloud ignored: %s", detail.c_str());
}

bool OdometryNodelet::bindFrames(const std::string& sensor_frame) {
  if (frames_) {
    if (frames_->sensor_frame == sensor_frame) return true;
    reject("sensor frame changed",
           "frame '" + sensor_frame + "' differs from the first cloud's frame '" + frames_->sensor_frame + "'");
    return false;
  }
  FrameBinding frames{settings_.odom_frame, sensor_frame, settings_.base_frame, Eigen::Isometry3d::Identity()};
  if (settings_.publish_sensor_frame_directly) {
    frames.child_frame = sensor_frame;
  } else if (sensor_frame != settings_.base_frame) {
    try {
      frames.base_from_sensor = tf2::transformToEigen(tf_buffer_->lookupTransform(
          settings_.base_frame, sensor_frame, ros::Time(0), ros::Duration(settings_.tf_timeout)));
    } catch (const tf2::TransformException& error) {
      reject("no sensor -> base transform",
             "no transform " + settings_.base_frame + " <- " + sensor_frame + " (" + error.what() +
                 "); publish it, or set ~publish_sensor_frame_directly when there is no " + settings_.base_frame);
      return false;
    }
  }
  // The extrinsic is fixed: the listener has done its work.
  tf_listener_.reset();
  tf_buffer_.reset();
  // The drive's map is built in the odom frame, where the child frame was at the first scan.
  session_->placeDriveMap([frames](const Eigen::Isometry3d& pose) { return frames.sensorPose(pose); });
  session_->withOdometry([&](elo::Odometry&, bool) { frames_ = frames; });
  return true;
}

void OdometryNodelet::processCloud(const QueuedCloud& queued) {
  const sensor_msgs::PointCloud2& message = *queued.message;
  const ConvertedCloud converted = fromPointCloud2(message);
  if (!converted.usable()) {
    reject(describe(converted.problem), converted.detail);
    return;
  }
  if (!bindFrames(message.header.frame_id)) return;
  if (!converted.time_problem.empty() && session_->config().deskew.time_source == elo::TimeSource::field) {
    // The core counts the scan as one without usable times (elo::FrameResult::time_warning).
    NODELET_WARN_THROTTLE(kWarningPeriod, "%s", converted.time_problem.c_str());
  }
  std_msgs::Header header;
  header.stamp = message.header.stamp;
  header.frame_id = frames_->sensor_frame;
  std::optional<ScanPublisher::Messages> messages;
  if (imu_) imu_->beforeScan(frames_->sensor_frame, converted.cloud.stamp);
  const elo::DriveStep step =
      session_->process(converted.cloud, [&](const elo::DriveStep& step, elo::Odometry& odometry) {
        if (step.restarted) publisher_->restart();
        if (step.odometry.processed) messages = publisher_->build(step, odometry, *frames_, header);
      });
  step_log_->log(step);
  if (imu_) imu_->afterScan();
  if (!step.odometry.processed) return;
  std::optional<LocalizationFace::Messages> localized;
  if (localization_) localized = localization_->update(step, *frames_, header.stamp);

  // After ros::shutdown the node only finishes its queue (for the trajectory): there is no one to tell.
  if (ros::ok()) {
    publisher_->publish(*messages);
    if (localized) localization_->publish(*localized);
  }
  const double latency_ms = std::chrono::duration<double, std::milli>(Clock::now() - queued.received).count();
  statistics_.scanProcessed(step.odometry, latency_ms);
  if (session_->feedMap(step, converted.cloud) == elo::DriveSession::MapFeed::dropped) {
    NODELET_WARN_THROTTLE(kWarningPeriod, "the map's thread fell behind: a scan left out of the drive's map");
  }
}

void OdometryNodelet::publishMap(const elo::DriveMap& map, const elo::MapScan& scan) {
  if (settings_.map_publish_period <= 0.0 || !ros::ok()) return;
  // Also when time went backwards (a bag replayed again): the map restarted with the odometry.
  const bool due = !last_map_stamp_ || scan.stamp >= *last_map_stamp_ + settings_.map_publish_period ||
                   scan.stamp < *last_map_stamp_;
  if (!due) return;
  last_map_stamp_ = scan.stamp;
  const size_t limit = static_cast<size_t>(settings_.map_publish_points);
  std_msgs::Header header;
  header.stamp.fromSec(scan.stamp);
  header.frame_id = settings_.odom_frame;
  // Thinned by the map itself, which then copies only the points shown.
  map_publisher_.publish(mapCloud(map.points((map.voxelCount() + limit - 1) / limit), 0, header));
}

}  // namespace elo_ros
