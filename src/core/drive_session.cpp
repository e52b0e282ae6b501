#include "elo/drive_session.hpp"

#include <cmath>
#include <stdexcept>
#include <utility>

#include "elapsed_time.hpp"

namespace elo {

DriveSession::DriveSession(const Config& config, DriveSessionOptions options)
    : options_(std::move(options)), odometry_(config) {
  if (options_.build_map) {
    map_ = std::make_unique<MapBuilder>(config.map, options_.map_queue, options_.after_map_scan);
  }
}

DriveSession::~DriveSession() = default;

void DriveSession::localizeIn(std::shared_ptr<const MapCloud> map, const std::optional<Eigen::Isometry3d>& initial_pose) {
  std::lock_guard<std::mutex> lock(odometry_mutex_);
  std::lock_guard<std::mutex> localization_lock(localization_mutex_);
  localizer_ = std::make_unique<Localizer>(odometry_, std::move(map));
  if (initial_pose) localizer_->setInitialPose(*initial_pose);
}

DriveStep DriveSession::process(const PointCloud& cloud, const WhileCurrent& while_current) {
  std::lock_guard<std::mutex> lock(odometry_mutex_);
  DriveStep step;
  step.stamp = cloud.stamp;
  step.odometry = odometry_.process(cloud);
  step.upload_milliseconds = odometry_.backend().lastUploadMilliseconds();
  follow(step);
  localize(step);
  record(step);
  if (while_current) while_current(step, odometry_);
  return step;
}

DriveStep DriveSession::skipUnreadable(double stamp, const std::string& reason) {
  std::lock_guard<std::mutex> lock(odometry_mutex_);
  ++unreadable_[reason];
  DriveStep step;
  step.stamp = stamp;
  step.odometry.skip_reason = reason;
  step.odometry.pose = odometry_.pose();
  follow(step);
  localize(step);
  record(step);
  return step;
}

void DriveSession::follow(DriveStep& step) {
  if (step.odometry.reset) restart();
  step.restarted = std::exchange(restart_pending_, false);
  step.generation = generation_;
  step.since_last_processed = last_processed_stamp_ ? step.stamp - *last_processed_stamp_ : 0.0;
  if (step.odometry.processed) last_processed_stamp_ = step.stamp;
}

void DriveSession::restart() {
  if (map_) map_->clear();
  ++generation_;
  last_processed_stamp_.reset();
  restart_pending_ = true;
  if (!options_.trajectory_restarts) return;
  trajectory_ = {};
  waiting_.clear();
}

void DriveSession::localize(DriveStep& step) {
  if (!localizer_) return;
  std::lock_guard<std::mutex> lock(localization_mutex_);
  try {
    step.localization = localizer_->update(step.odometry);
    last_localized_ = step.localization;
  } catch (const std::exception& error) {
    step.localization_failure = error.what();
  }
}

void DriveSession::record(const DriveStep& step) {
  trajectory_.stamps.push_back(step.stamp);
  trajectory_.odometry.push_back(step.odometry.pose);
  if (!localizer_) return;
  if (!step.localization) {  // the localizer failed: the odometry's pose, carried by the last correction
    trajectory_.in_map.push_back(localizer_->mapFromOdom() * step.odometry.pose);
    return;
  }
  const LocalizationResult& localized = *step.localization;
  trajectory_.in_map.push_back(localized.pose);
  if (localized.state == LocalizationState::waiting_for_pose) {
    waiting_.push_back(trajectory_.in_map.size() - 1);
    return;
  }
  if (!localized.matched || waiting_.empty()) return;
  trajectory_.placements.push_back({localized.map_correction, std::move(waiting_)});
  waiting_.clear();
}

DriveSession::MapFeed DriveSession::feedMap(const DriveStep& step, const PointCloud& cloud) {
  const FrameResult& result = step.odometry;
  if (!map_ || !result.processed || !result.refusal.empty()) return MapFeed::left_out;
  std::lock_guard<std::mutex> lock(odometry_mutex_);
  if (step.generation != generation_) return MapFeed::left_out;  // restarted since: another frame
  ++map_feed_.processed;
  if (result.registration.degeneracy.any()) {
    ++map_feed_.degenerate;
    return MapFeed::left_out;
  }
  if (!map_->takesNextScan()) return MapFeed::left_out;
  const double start = threadCpuSeconds();
  // Only the scans' thread processes scans: the backend still holds this one.
  const Eigen::Isometry3d pose = map_placement_ ? map_placement_(odometry_.modelPose()) : odometry_.modelPose();
  MapScan scan = mapScanOf(odometry_.backend().scan(), cloud, pose, cloud.stamp, odometry_.config().map.voxel_size);
  map_feed_.copy_seconds += threadCpuSeconds() - start;
  return map_->add(std::move(scan)) ? MapFeed::queued : MapFeed::dropped;
}

void DriveSession::placeDriveMap(MapPlacement placement) {
  std::lock_guard<std::mutex> lock(odometry_mutex_);
  map_placement_ = std::move(placement);
}

void DriveSession::addImu(const ImuSample& sample) {
  std::lock_guard<std::mutex> lock(odometry_mutex_);
  odometry_.addImu(sample);
}

void DriveSession::setImuMount(const std::vector<double>& position, const std::vector<double>& rotation_deg) {
  std::lock_guard<std::mutex> lock(odometry_mutex_);
  odometry_.setImuMount(position, rotation_deg);
}

ImuStatus DriveSession::imuStatus() const {
  std::lock_guard<std::mutex> lock(odometry_mutex_);
  return odometry_.imuStatus();
}

void DriveSession::reset() {
  std::lock_guard<std::mutex> lock(odometry_mutex_);
  odometry_.reset();
  if (localizer_) {
    std::lock_guard<std::mutex> localization_lock(localization_mutex_);
    localizer_->odometryRestarted();
  }
  restart();
}

void DriveSession::setInitialPose(const Eigen::Isometry3d& map_from_sensor) {
  // The odometry's lock too: a hint is placed by the pose the odometry carries.
  std::lock_guard<std::mutex> lock(odometry_mutex_);
  std::lock_guard<std::mutex> localization_lock(localization_mutex_);
  if (localizer_) localizer_->setInitialPose(map_from_sensor);
}

DriveSession::Relocalization DriveSession::relocalize() {
  std::lock_guard<std::mutex> lock(odometry_mutex_);
  std::lock_guard<std::mutex> localization_lock(localization_mutex_);
  if (!localizer_) return Relocalization::no_pose_yet;
  // Not tracking: around the hint the odometry carries, at once rather than at its next periodic search.
  if (const std::optional<PoseHint> carried = localizer_->carriedHint()) {
    localizer_->setInitialPose(carried->map_from_sensor, carried->radius, carried->yaw_deg);
    return Relocalization::around_carried_hint;
  }
  if (localizer_->state() == LocalizationState::waiting_for_pose) return Relocalization::no_pose_yet;
  localizer_->setInitialPose(last_localized_ ? last_localized_->pose : Eigen::Isometry3d::Identity());
  return Relocalization::around_current_pose;
}

void DriveSession::withOdometry(const std::function<void(Odometry& odometry, bool processed)>& use) {
  std::lock_guard<std::mutex> lock(odometry_mutex_);
  use(odometry_, last_processed_stamp_.has_value());
}

DriveTrajectory DriveSession::trajectory() const {
  std::lock_guard<std::mutex> lock(odometry_mutex_);
  return trajectory_;
}

Eigen::Isometry3d poseFromXyzYaw(const std::vector<double>& xyz_yaw_deg) {
  if (xyz_yaw_deg.size() != 4) throw std::invalid_argument("a pose needs x, y, z and yaw_deg");
  const std::vector<double>& v = xyz_yaw_deg;
  return Eigen::Translation3d(v[0], v[1], v[2]) * Eigen::AngleAxisd(v[3] * M_PI / 180.0, Eigen::Vector3d::UnitZ());
}

}  // namespace elo
