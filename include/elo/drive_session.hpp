// One drive through the core (docs/architecture.md): a scan and its stamp in; the odometry, the
// localization in a saved map when one is loaded, the drive's map and the trajectory; one DriveStep out.
// The ROS nodelet and elo_run are shells over it: they read scans and write what it returns, so that
// what happens to a scan after the odometry is written once.
#pragma once

#include <Eigen/Geometry>
#include <functional>
#include <map>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <vector>

#include "elo/localization/localizer.hpp"
#include "elo/map/map_builder.hpp"
#include "elo/pipeline/odometry.hpp"

namespace elo {

struct DriveSessionOptions {
  // The drive's map (docs/map.md), built on a thread of its own; none when false.
  bool build_map = false;
  size_t map_queue = 8;                  // scans waiting for the map's thread (MapBuilder)
  MapBuilder::AfterScan after_map_scan;  // on the map's thread after each scan (the node publishes it)
  // Whether the trajectory starts again when the odometry restarts at the origin (reset(), or time
  // going backwards): the node's does, its earlier poses lying in another frame; elo_run's keeps one
  // line per scan played, aligned with the ground truth.
  bool trajectory_restarts = false;
};

// One line per scan given to the session; a skipped scan's line repeats the last pose.
struct DriveTrajectory {
  std::vector<double> stamps;
  std::vector<Eigen::Isometry3d> odometry;  // the sensor in the first scan's sensor frame
  // Localizing: the sensor in the map (LocalizationResult::pose); while waiting for a pose, the odometry's.
  std::vector<Eigen::Isometry3d> in_map;
  // Each accepted match that ended a wait for a pose: its correction (LocalizationResult::map_correction)
  // and the lines of in_map written while waiting, which it places in the map: correction * in_map[line].
  // Applied by the shell that writes them (elo_run), so that the product rounds as it did there before.
  struct Placement {
    Eigen::Isometry3d correction = Eigen::Isometry3d::Identity();
    std::vector<size_t> lines;
  };
  std::vector<Placement> placements;
};

// What the session made of one scan.
struct DriveStep {
  double stamp = 0.0;
  FrameResult odometry;
  // Seconds since the trajectory's last processed scan, 0 at its first: a processed scan's interval.
  double since_last_processed = 0.0;
  // The trajectory restarted at the origin before or at this scan (reset(), or FrameResult::reset): what a
  // shell keeps of it (the node's path) starts again.
  bool restarted = false;
  double upload_milliseconds = 0.0;  // Backend::lastUploadMilliseconds() after this scan
  // Localizing: this scan in the map; nullopt when the localizer failed on it (localization_failure says
  // why, as for a backend that cannot render the map near the vehicle) and the scan keeps the odometry's pose.
  std::optional<LocalizationResult> localization;
  std::string localization_failure;
  size_t generation = 0;  // the restarts before this scan: feedMap() leaves out a scan from before one
};

// Counts of what feedMap() did, for elo_run's summary.
struct MapFeedStatistics {
  size_t processed = 0;       // processed scans whose registration was accepted
  size_t degenerate = 0;      // of them, left out: a direction was degenerate
  double copy_seconds = 0.0;  // CPU time copying points out on the scans' thread
};

class DriveSession {
 public:
  // Throws as Odometry and Localizer do (ConfigError, std::runtime_error, std::invalid_argument).
  explicit DriveSession(const Config& config, DriveSessionOptions options = {});
  ~DriveSession();  // adds the queued scans to the map, then stops its thread
  DriveSession(const DriveSession&) = delete;
  DriveSession& operator=(const DriveSession&) = delete;

  // Localizes every scan from the next in `map` (prepared: readPreparedMap(), elo/io/map_pcd.hpp), from
  // `initial_pose` (the sensor in the map at the first scan; none: wait for one). Before the first scan.
  // Throws std::invalid_argument for a map the Localizer cannot use.
  void localizeIn(std::shared_ptr<const MapCloud> map, const std::optional<Eigen::Isometry3d>& initial_pose);

  // Called by process() while the backend still holds the scan (Backend::scan(), Backend::model(),
  // Odometry::modelPose()) and no other call can change the session: the node builds its messages there.
  using WhileCurrent = std::function<void(const DriveStep& step, Odometry& odometry)>;

  // The odometry on `cloud`, then its localization (a step of its own, under its own lock), and the
  // trajectory's line. Scans come from one thread.
  DriveStep process(const PointCloud& cloud, const WhileCurrent& while_current = {});
  // A scan that could not be read or used before reaching the odometry, counted under `reason`: its line
  // repeats the last pose, and a localizer is told of it as of a skipped scan.
  DriveStep skipUnreadable(double stamp, const std::string& reason);
  // Any thread: an IMU sample (Odometry::addImu(); imu.enabled, docs/imu.md), in time order, before the
  // scans whose sweeps it covers.
  void addImu(const ImuSample& sample);
  // Any thread: Odometry::setImuMount() (the node's mount from TF), and Odometry::imuStatus().
  void setImuMount(const std::vector<double>& position, const std::vector<double>& rotation_deg);
  ImuStatus imuStatus() const;
  // Odometry::prefetch(): the scan a later process() call will be given.
  void prefetch(const PointCloud& cloud) { odometry_.prefetch(cloud); }

  enum class MapFeed { left_out, queued, dropped };
  // Hands `step`'s scan (`cloud`, the one processed) to the drive map's thread, when the map takes it
  // (MapConfig::scan_stride): called after a shell wrote the scan's outputs, so that the map never
  // delays a pose, and before the next scan. A refused or degenerate registration places the scan by
  // the motion prior, in some direction or altogether: left out, as is a scan from before a restart.
  // `dropped`: the map's thread fell behind and the scan was left out.
  MapFeed feedMap(const DriveStep& step, const PointCloud& cloud);
  // Where the drive map puts a scan the core places at `sensor_pose` (Odometry::modelPose(), in the first
  // scan's sensor frame): the node's map is in its odom frame (FrameBinding::sensorPose()). Unset, the
  // pose as it is. Before the first scan fed.
  using MapPlacement = std::function<Eigen::Isometry3d(const Eigen::Isometry3d& sensor_pose)>;
  void placeDriveMap(MapPlacement placement);

  // Any thread: the next scan starts a new trajectory at the origin (Odometry::reset()).
  void reset();
  // Any thread, localizing: the next scan searches around `map_from_sensor` (Localizer::setInitialPose()).
  void setInitialPose(const Eigen::Isometry3d& map_from_sensor);
  enum class Relocalization { around_carried_hint, around_current_pose, no_pose_yet };
  // Any thread, localizing: the next scan searches around the pose the odometry carries while not
  // tracking, or around the current pose in the map; no_pose_yet (nothing changed) while waiting for one.
  Relocalization relocalize();

  // Any thread: `use` runs while no scan is processed; `processed`: a scan was since the trajectory began.
  void withOdometry(const std::function<void(Odometry& odometry, bool processed)>& use);
  // Any thread: a copy of the trajectory.
  DriveTrajectory trajectory() const;

  // From the scans' thread, or while none is processed (elo_run's summary):
  const Odometry& odometry() const { return odometry_; }
  const Config& config() const { return odometry_.config(); }
  // The drive's map (thread-safe itself); null without DriveSessionOptions::build_map.
  MapBuilder* driveMap() { return map_.get(); }
  const MapFeedStatistics& mapFeedStatistics() const { return map_feed_; }
  const Localizer* localizer() const { return localizer_.get(); }
  // Scans counted by skipUnreadable(), by reason.
  const std::map<std::string, size_t>& unreadableCounts() const { return unreadable_; }
  // Localizing: the lines the last wait's match placed in the map, and those still waiting for one.
  size_t linesPlacedByFirstMatch() const {
    return trajectory_.placements.empty() ? 0 : trajectory_.placements.back().lines.size();
  }
  size_t linesWaitingForMatch() const { return waiting_.size(); }

 private:
  // Under odometry_mutex_: after the odometry's result, the restart it may say and the interval.
  void follow(DriveStep& step);
  // Under odometry_mutex_: the map, the trajectory (with the node's option) and the interval forgotten.
  void restart();
  // Under odometry_mutex_; takes localization_mutex_.
  void localize(DriveStep& step);
  // Under odometry_mutex_: the step's line; a first match takes the lines waiting for it.
  void record(const DriveStep& step);

  DriveSessionOptions options_;
  // Guards everything below but the localizer; taken before localization_mutex_.
  mutable std::mutex odometry_mutex_;
  Odometry odometry_;
  DriveTrajectory trajectory_;
  std::vector<size_t> waiting_;  // lines of trajectory_.in_map written while waiting for a pose
  std::optional<double> last_processed_stamp_;
  bool restart_pending_ = false;  // reset() since the last scan
  size_t generation_ = 0;
  std::map<std::string, size_t> unreadable_;
  MapPlacement map_placement_;
  MapFeedStatistics map_feed_;
  // Guards the localizer: its step after each scan, and the requests from other threads.
  std::mutex localization_mutex_;
  std::unique_ptr<Localizer> localizer_;
  std::optional<LocalizationResult> last_localized_;
  std::unique_ptr<MapBuilder> map_;  // last: its thread stops first
};

// The sensor's pose from [x, y, z, yaw_deg] (elo_run --initial-pose, the node's ~initial_pose): yaw about
// z, in degrees. A z of NaN leaves the height to the map's ground (Localizer::setInitialPose()).
Eigen::Isometry3d poseFromXyzYaw(const std::vector<double>& xyz_yaw_deg);

}  // namespace elo
