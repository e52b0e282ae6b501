#include "odometry_nodelet.hpp"

#include <tf2_eigen/tf2_eigen.h>

#include "cloud_conversion.hpp"
#include "elo/io/kitti.hpp"
#include "elo/io/map_pcd.hpp"
#include "elo/io/pcd.hpp"
#include "elo/sensor_fit.hpp"

namespace elo_ros {
namespace {

using Clock = std::chrono::steady_clock;

constexpr double kWarningPeriod = 5.0;  // s between repeats of one throttled warning
// Scans waiting for the map's thread: a second of a 10 Hz sensor (about 15 MB for an HDL-64E). The map
// adds a scan in a few milliseconds; the queue fills only when its thread gets no CPU for a second.
constexpr size_t kMapQueue = 10;

std::string joined(const std::vector<std::string>& names) {
  std::string text;
  for (const std::string& name : names) text += (text.empty() ? "" : ", ") + name;
  return text;
}

}  // namespace

void OdometryNodelet::onInit() {
  try {
    settings_ = readNodeSettings(getPrivateNodeHandle());
    odometry_ = std::make_unique<elo::Odometry>(loadConfig());
  } catch (const std::exception& error) {
    NODELET_FATAL("cannot start: %s", error.what());
    throw;
  }
  if (!odometry_->backendWarning().empty()) NODELET_WARN("%s", odometry_->backendWarning().c_str());
  const std::string normal_reach = elo::normalReachWarning(odometry_->config());
  if (!normal_reach.empty()) NODELET_WARN("%s", normal_reach.c_str());
  if (settings_.build_map) {
    map_ = std::make_unique<elo::MapBuilder>(odometry_->config().map, kMapQueue,
                                             [this](const elo::DriveMap& map, const elo::MapScan& scan) { publishMap(map, scan); });
  }
  if (!settings_.publish_sensor_frame_directly) {
    tf_buffer_ = std::make_unique<tf2_ros::Buffer>();
    tf_listener_ = std::make_unique<tf2_ros::TransformListener>(*tf_buffer_, getNodeHandle());
  }
  tf_broadcaster_ = std::make_unique<tf2_ros::TransformBroadcaster>();
  advertise();
  try {
    const LocalizationSettings localization = readLocalizationSettings(getPrivateNodeHandle());
    if (!localization.map_file.empty()) {
      localization_ = std::make_unique<LocalizationFace>(getNodeHandle(), getPrivateNodeHandle(), localization,
                                                         *odometry_, odometry_mutex_);
    }
  } catch (const std::exception& error) {
    NODELET_FATAL("cannot start localization: %s", error.what());
    throw;
  }

  diagnostics_ = std::make_unique<diagnostic_updater::Updater>(getNodeHandle(), getPrivateNodeHandle(), getName());
  diagnostics_->setHardwareID(odometry_->config().sensor.name);
  diagnostics_->add("odometry", &statistics_, &PipelineStatistics::report);
  if (localization_) diagnostics_->add("localization", localization_.get(), &LocalizationFace::report);
  // A wall timer: diagnostics must keep coming while a replayed clock is paused or not yet started.
  diagnostics_timer_ = getNodeHandle().createWallTimer(ros::WallDuration(1.0),
                                                       [this](const ros::WallTimerEvent&) { diagnostics_->force_update(); });

  // 0: every scan is queued (bag replay); 1: only the latest waits, older ones are dropped and counted.
  queue_ = std::make_unique<ScanQueue>(settings_.process_every_scan ? 0 : 1);
  worker_ = std::thread([this] { runWorker(); });
  // roscpp's own queue stays unbounded when every scan counts; the callback empties it at once anyway.
  const uint32_t subscriber_queue = settings_.process_every_scan ? 0 : 5;
  cloud_subscriber_ = getNodeHandle().subscribe("points", subscriber_queue, &OdometryNodelet::onCloud, this);

  const elo::Config& config = odometry_->config();
  NODELET_INFO("ELO odometry on %s: sensor %s, %s backend, %d threads (0 = all), %s, %s; publishing %s -> %s",
               cloud_subscriber_.getTopic().c_str(), config.sensor.name.c_str(), odometry_->backend().name(),
               config.runtime.threads,
               config.model.mode == elo::RegistrationMode::frame_to_model ? "frame-to-model" : "frame-to-frame",
               settings_.process_every_scan ? "every scan processed" : "latest scan processed",
               settings_.odom_frame.c_str(),
               settings_.publish_sensor_frame_directly ? "<sensor frame>" : settings_.base_frame.c_str());
}

elo::Config OdometryNodelet::loadConfig() {
  ros::NodeHandle& private_node = getPrivateNodeHandle();
  XmlRpc::XmlRpcValue tree;
  private_node.getParam(private_node.getNamespace(), tree);
  elo::Config config;
  const std::vector<std::string> unknown = applyConfigParameters(tree, config);
  if (!unknown.empty()) {
    NODELET_WARN("unknown parameters ignored (no such odometry parameter, see config/*.yaml): %s",
                 joined(unknown).c_str());
  }
  elo::validate(config);
  for (const auto& [name, value] : effectiveParameters(config)) private_node.setParam(name, value);
  return config;
}

void OdometryNodelet::advertise() {
  ros::NodeHandle& node = getNodeHandle();
  odometry_publisher_ = node.advertise<nav_msgs::Odometry>("odom", 100);
  path_publisher_ = node.advertise<nav_msgs::Path>("path", 1);
  model_nonground_publisher_ = node.advertise<sensor_msgs::PointCloud2>("model/nonground", 1);
  model_ground_publisher_ = node.advertise<sensor_msgs::PointCloud2>("model/ground", 1);
  scan_ground_publisher_ = node.advertise<sensor_msgs::PointCloud2>("scan/ground", 1);
  scan_nonground_publisher_ = node.advertise<sensor_msgs::PointCloud2>("scan/nonground", 1);
  // Latched: rviz, started late, still shows the map.
  if (map_) map_publisher_ = node.advertise<sensor_msgs::PointCloud2>("map", 1, true);
  ros::NodeHandle& private_node = getPrivateNodeHandle();
  reset_service_ = private_node.advertiseService("reset", &OdometryNodelet::onReset, this);
  save_trajectory_service_ = private_node.advertiseService("save_trajectory", &OdometryNodelet::onSaveTrajectory, this);
  save_map_service_ = private_node.advertiseService("save_map", &OdometryNodelet::onSaveMap, this);
  save_model_service_ = private_node.advertiseService("save_model", &OdometryNodelet::onSaveModel, this);
}

OdometryNodelet::~OdometryNodelet() {
  if (!queue_) return;  // onInit failed: nothing started
  cloud_subscriber_.shutdown();
  diagnostics_timer_.stop();
  const size_t waiting = queue_->size();
  if (waiting > 0) NODELET_INFO("finishing %zu queued scans before stopping", waiting);
  queue_->close();
  worker_.join();
  map_.reset();  // its thread publishes through members destroyed before it
  if (!settings_.save_trajectory_on_shutdown) return;
  try {
    NODELET_INFO("%s", saveTrajectory(settings_.outputs).c_str());
  } catch (const std::exception& error) {
    NODELET_ERROR("cannot save the trajectory on shutdown: %s", error.what());
  }
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
  std::lock_guard<std::mutex> lock(odometry_mutex_);
  frames_ = frames;
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
  if (!converted.time_problem.empty() && odometry_->config().deskew.time_source == elo::TimeSource::field) {
    // The core counts the scan as one without usable times (elo::FrameResult::time_warning).
    NODELET_WARN_THROTTLE(kWarningPeriod, "%s", converted.time_problem.c_str());
  }

  std::unique_lock<std::mutex> lock(odometry_mutex_);
  const elo::FrameResult result = odometry_->process(converted.cloud);
  reportRestart(result, converted.cloud.stamp);
  // Every scan the core saw, a skipped one repeating the last pose: the lines match elo_run's.
  trajectory_stamps_.push_back(converted.cloud.stamp);
  trajectory_poses_.push_back(result.pose);
  if (!result.time_warning.empty()) {
    NODELET_WARN_THROTTLE(kWarningPeriod, "per-point times: %s (deskew.time_source)", result.time_warning.c_str());
  }
  if (!result.sensor_warning.empty()) NODELET_WARN_THROTTLE(kWarningPeriod, "%s", result.sensor_warning.c_str());
  logStartSearch(result.start_search);
  logTrackingHealth(result);
  if (!result.processed) {
    lock.unlock();
    statistics_.scanSkipped(result.skip_reason);
    NODELET_WARN_THROTTLE(kWarningPeriod, "scan skipped: %s", result.skip_reason.c_str());
    return;
  }
  const double dt = last_processed_stamp_ ? converted.cloud.stamp - *last_processed_stamp_ : 0.0;
  last_processed_stamp_ = converted.cloud.stamp;
  std_msgs::Header header;
  header.stamp = message.header.stamp;
  header.frame_id = frames_->sensor_frame;
  const ScanMessages messages = buildMessages(result, dt, header);
  const Eigen::Isometry3d map_pose = frames_->sensorPose(odometry_->modelPose());
  const size_t map_generation = map_generation_;
  lock.unlock();

  // After ros::shutdown the node only finishes its queue (for the trajectory): there is no one to tell.
  if (ros::ok()) publish(messages);
  const double latency_ms = std::chrono::duration<double, std::milli>(Clock::now() - queued.received).count();
  statistics_.scanProcessed(result, latency_ms);
  feedMap(result, converted.cloud, map_pose, map_generation);
}

void OdometryNodelet::logTrackingHealth(const elo::FrameResult& result) {
  if (!result.sensor_height_warning.empty()) NODELET_WARN("%s", result.sensor_height_warning.c_str());
  if (result.tracking_restart) {
    NODELET_ERROR("lost: registrations refused %d times in a row (%s); the model restarts from this scan",
                  odometry_->config().motion.restart_after, result.refusal.c_str());
  } else if (!result.refusal.empty()) {
    NODELET_WARN_THROTTLE(kWarningPeriod, "registration refused (%s): the pose is the motion prior's",
                          result.refusal.c_str());
  }
  if (result.recovered) NODELET_INFO("tracking recovered after refused registrations");
}

void OdometryNodelet::logStartSearch(const elo::StartSearchResult& search) {
  if (!search.searched) return;
  const Eigen::Vector3d moved = search.motion.translation();
  if (search.ambiguous) {
    NODELET_WARN("start in motion: ambiguous, another motion fits the first two scans about as well (score %.3f "
                 "against %.3f); taken: %.2f m forward, which the scans do not confirm",
                 search.score, search.rival_score, moved.x());
  } else {
    NODELET_INFO("start in motion: %.2f m forward between the first two scans (%d candidates, %.0f ms)", moved.x(),
                 search.candidates, search.milliseconds);
  }
}

void OdometryNodelet::feedMap(const elo::FrameResult& result, const elo::PointCloud& cloud,
                              const Eigen::Isometry3d& sensor_pose, size_t generation) {
  // Registered with a degenerate direction, the scan's pose along it is the motion prior's, and a refused
  // scan's pose is the prior's altogether: left out.
  if (!map_ || result.registration.degeneracy.any() || !result.refusal.empty()) return;
  std::unique_lock<std::mutex> lock(odometry_mutex_);
  if (generation != map_generation_) return;  // ~reset since: the pose lies in the old odom frame
  if (!map_->takesNextScan()) return;
  // Only this thread processes scans: the backend still holds this one.
  elo::MapScan scan = elo::mapScanOf(odometry_->backend().scan(), cloud, sensor_pose, cloud.stamp,
                                     odometry_->config().map.voxel_size);
  if (!map_->add(std::move(scan))) {
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

void OdometryNodelet::reportRestart(const elo::FrameResult& result, double stamp) {
  if (result.reset) {
    NODELET_WARN("time went backwards (a bag replayed again?): the odometry restarted at the origin");
    statistics_.odometryRestarted("time went backwards");
    forgetTrajectory();
  }
  if (result.gap_restart) {
    NODELET_WARN("no scan for %.1f s, longer than model.time_window (%.1f s): the model restarted at the last pose, "
                 "and the odometry leaves out the motion during the gap",
                 stamp - last_processed_stamp_.value_or(stamp), odometry_->config().model.time_window);
    statistics_.odometryRestarted("gap longer than model.time_window");
  }
}

OdometryNodelet::ScanMessages OdometryNodelet::buildMessages(const elo::FrameResult& result, double dt,
                                                             const std_msgs::Header& header) {
  ScanMessages messages;
  messages.odometry = odometryMessage(result, dt, *frames_, header.stamp);

  geometry_msgs::PoseStamped pose;
  pose.header = messages.odometry.header;
  pose.pose = messages.odometry.pose.pose;
  path_.push_back(pose);
  if (settings_.path_length > 0 && path_.size() > static_cast<size_t>(settings_.path_length)) path_.pop_front();
  if (path_publisher_.getNumSubscribers() > 0) {
    messages.path.emplace();
    messages.path->header = messages.odometry.header;
    messages.path->poses.assign(path_.begin(), path_.end());
  }

  // The models are large; they go out at most model_publish_rate times per second of scan time.
  const double stamp = header.stamp.toSec();
  const bool models_wanted =
      model_nonground_publisher_.getNumSubscribers() > 0 || model_ground_publisher_.getNumSubscribers() > 0;
  if (settings_.model_publish_rate > 0.0 && models_wanted && stamp >= next_model_stamp_) {
    next_model_stamp_ = stamp + 1.0 / settings_.model_publish_rate;
    // In the sensor frame at the scan's reference instant, as are the labelled scans below: mid-sweep for
    // per-point times from the cloud, a fraction of the sweep's motion from the stamp (docs/deskew.md).
    const elo::Model& model = odometry_->backend().model();
    messages.model_nonground = nonGroundModelCloud(model.nonground, header);
    messages.model_ground = groundModelCloud(model.ground, header);
  }
  if (scan_ground_publisher_.getNumSubscribers() > 0) {
    messages.scan_ground = labelledScanCloud(odometry_->backend().scan(), elo::PixelLabel::ground, header);
  }
  if (scan_nonground_publisher_.getNumSubscribers() > 0) {
    messages.scan_nonground = labelledScanCloud(odometry_->backend().scan(), elo::PixelLabel::nonground, header);
  }
  if (localization_) messages.localization = localization_->update(result, *frames_, header.stamp);
  return messages;
}

void OdometryNodelet::publish(const ScanMessages& messages) {
  odometry_publisher_.publish(messages.odometry);
  if (settings_.publish_tf) tf_broadcaster_->sendTransform(odometryTransform(messages.odometry));
  if (messages.path) path_publisher_.publish(*messages.path);
  if (messages.model_nonground) model_nonground_publisher_.publish(*messages.model_nonground);
  if (messages.model_ground) model_ground_publisher_.publish(*messages.model_ground);
  if (messages.scan_ground) scan_ground_publisher_.publish(*messages.scan_ground);
  if (messages.scan_nonground) scan_nonground_publisher_.publish(*messages.scan_nonground);
  if (messages.localization) localization_->publish(*messages.localization);
}

void OdometryNodelet::forgetTrajectory() {
  trajectory_stamps_.clear();
  trajectory_poses_.clear();
  path_.clear();
  if (map_) map_->clear();
  ++map_generation_;
  last_processed_stamp_.reset();
  next_model_stamp_ = -std::numeric_limits<double>::infinity();
}

bool OdometryNodelet::onReset(std_srvs::Trigger::Request&, std_srvs::Trigger::Response& response) {
  std::lock_guard<std::mutex> lock(odometry_mutex_);
  odometry_->reset();
  if (localization_) localization_->odometryReset();
  forgetTrajectory();
  response.success = true;
  response.message = "odometry reset: the next scan starts a new trajectory at the origin";
  NODELET_INFO("%s", response.message.c_str());
  return true;
}

std::string OdometryNodelet::saveTrajectory(const OutputFiles& files) {
  if (files.trajectory_file.empty()) throw std::invalid_argument("~trajectory_file is not set");
  const TrajectoryFormat format = parseTrajectoryFormat(files.trajectory_format);
  std::lock_guard<std::mutex> lock(odometry_mutex_);
  if (format == TrajectoryFormat::kitti) {
    elo::writeKittiPoses(files.trajectory_file, trajectory_poses_);
  } else {
    elo::writeTumPoses(files.trajectory_file, trajectory_stamps_, trajectory_poses_);
  }
  return "wrote " + std::to_string(trajectory_poses_.size()) + " sensor poses (" + files.trajectory_format +
         ") to " + files.trajectory_file;
}

bool OdometryNodelet::onSaveTrajectory(std_srvs::Trigger::Request&, std_srvs::Trigger::Response& response) {
  try {
    response.message = saveTrajectory(readOutputFiles(getPrivateNodeHandle()));
    response.success = true;
  } catch (const std::exception& error) {
    response.message = error.what();
    response.success = false;
  }
  return true;
}

bool OdometryNodelet::onSaveMap(std_srvs::Trigger::Request&, std_srvs::Trigger::Response& response) {
  try {
    const OutputFiles files = readOutputFiles(getPrivateNodeHandle());
    if (files.map_file.empty()) throw std::invalid_argument("~map_file is not set");
    if (!map_) throw std::runtime_error("~build_map is false: no map was built");
    // Every scan processed so far is in the map once it returns.
    const elo::MapCloud map = map_->points();
    elo::writeMapPcd(files.map_file, map);
    const elo::MapBuilder::Statistics statistics = map_->statistics();
    response.message = "wrote the drive's map, " + std::to_string(map.size()) + " points from " +
                       std::to_string(statistics.scans) + " scans (" + settings_.odom_frame + " frame), to " +
                       files.map_file;
    response.success = true;
  } catch (const std::exception& error) {
    response.message = error.what();
    response.success = false;
  }
  return true;
}

bool OdometryNodelet::onSaveModel(std_srvs::Trigger::Request&, std_srvs::Trigger::Response& response) {
  try {
    const OutputFiles files = readOutputFiles(getPrivateNodeHandle());
    if (files.model_file.empty()) throw std::invalid_argument("~model_file is not set");
    std::lock_guard<std::mutex> lock(odometry_mutex_);
    if (!frames_ || !last_processed_stamp_) throw std::runtime_error("no scan processed yet: the model is empty");
    // The model lives in the latest scan's frame at its reference instant (mid-sweep for per-point times
    // from the cloud: Odometry::modelPose()); the file holds it in the odom frame.
    const elo::PointCloud map =
        modelPoints(odometry_->backend().model(), frames_->sensorPose(odometry_->modelPose()));
    elo::writePcd(files.model_file, map);
    response.message = "wrote " + std::to_string(map.size()) + " model points (" + settings_.odom_frame +
                       " frame) to " + files.model_file;
    response.success = true;
  } catch (const std::exception& error) {
    response.message = error.what();
    response.success = false;
  }
  return true;
}

}  // namespace elo_ros
