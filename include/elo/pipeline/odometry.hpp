// The ELO pipeline (Fig. 2): predict -> project -> segment ground -> normals -> BEV -> register ->
// update the model. ROS-free; the nodelet and the tools are thin shells around this class.
#pragma once

#include <Eigen/Geometry>
#include <map>
#include <memory>
#include <optional>
#include <string>

#include "elo/pipeline/backend.hpp"
#include "elo/config.hpp"
#include "elo/pipeline/deskew.hpp"
#include "elo/imu/imu_track.hpp"
#include "elo/imu/inertial_filter.hpp"
#include "elo/imu/tilt_hold.hpp"
#include "elo/pipeline/motion_prior.hpp"
#include "elo/pipeline/registration.hpp"
#include "elo/sensor/sensor_height_check.hpp"
#include "elo/pipeline/start_search.hpp"
#include "elo/pipeline/tracking_guard.hpp"

namespace elo {

// Wall time of each stage (ms), split as the paper's Table V.
struct StageTimes {
  double projection = 0.0;
  double feature_extraction = 0.0;  // ground segmentation + normals + BEV map
  double registration = 0.0;  // deskew rounds within it excluded, a start search included
  double deskew = 0.0;  // deskewing the scan again in place and rebuilding its ground map, over the rounds
  double model_update = 0.0;
  double total = 0.0;
};

struct FrameResult {
  bool processed = false;
  std::string skip_reason;  // why the scan was not used, when !processed
  bool reset = false;       // the odometry restarted at this scan (time went backwards)
  // The gap since the previous scan exceeded model.time_window: the model and the motion prior restarted
  // at the last pose, which this scan keeps (the motion during the gap is unknown).
  bool gap_restart = false;
  // The interval (s) since the scan before, when it exceeded start_search.after_gap_periods times the
  // usual one (a shorter gap than time_window: dropped scans, or a clock that jumped forward); 0 otherwise.
  // The motion prior did not hold across it: the motion was searched (start_search) and gave no velocity.
  double gap = 0.0;
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();   // sensor in the odometry frame
  Eigen::Isometry3d delta = Eigen::Isometry3d::Identity();  // T^{t-1}_t
  RegistrationResult registration;  // of the last round
  // The start in motion: the search for the motion of a scan registered with none known (searched: the
  // first registration after a start, a reset or a restart, with start_search.enabled).
  StartSearchResult start_search;
  // Tracking health (docs/robustness.md#a-lost-track). Why the registration was refused (a
  // refusal:: reason of tracking_guard.hpp), empty when it was accepted; a registration from the prior
  // that is refused is searched and registered again first, and this is that second one's reason. A refused scan is processed, but
  // its pose is the motion prior's and it changed neither the model nor the velocity.
  std::string refusal;
  bool recovered = false;         // accepted after refused ones
  // motion.restart_after refusals in a row: the model restarted from this scan, at the refused pose.
  bool tracking_restart = false;
  // Deskewed under the last velocity the scan filled too few pixels; projected again without deskew.
  bool projected_without_deskew = false;
  // The ground the scans show lies far from ground.sensor_height (SensorHeightCheck::add()); empty when
  // it does not, or was told already.
  std::string sensor_height_warning;
  // With imu.enabled: why the gyro could not turn this scan's prior and deskew (imu_issue::), which then
  // were the LiDAR's alone; empty when it did.
  std::string imu_fallback;
  // Motion compensation (docs/deskew.md): where the points' times came from (none: the scan was taken as
  // instantaneous), the rounds of deskewing again with the registered motion, and why the cloud's own
  // times were not used or not all used (empty when they were, or when none were asked for).
  TimeSource time_source = TimeSource::none;
  int deskew_rounds = 0;
  std::string time_warning;
  size_t points_without_time = 0;  // points dropped for a time outside the sweep
  // Why much of the scan does not fit the configured sensor (SensorFit::warning()); empty when it fits.
  std::string sensor_warning;
  StageTimes times;
};

class Odometry {
 public:
  // Throws ConfigError for an unusable config and std::runtime_error for an unavailable backend.
  explicit Odometry(const Config& config);

  // Processes one sweep. A scan that cannot be used (empty, too few valid points, a stamp that is not
  // finite or repeats the last one to the nanosecond) is skipped, counted under its reason and leaves the state as it was.
  // A stamp before the last one resets (see reset()); one more than model.time_window after it restarts
  // the model at the current pose (FrameResult::gap_restart). A scan whose motion is unknown has it
  // searched (FrameResult::start_search); a registration beyond what the platform can do is refused
  // (FrameResult::refusal: the scan is processed, its pose the motion prior's). It returns, normally or
  // by an exception, only once the backend no longer reads a cloud handed to prefetch().
  FrameResult process(const PointCloud& cloud);

  // An IMU sample (imu.enabled; docs/imu.md), in time order, before the scans it covers: the gyro turns
  // the motion prior and the deskew of the scans whose sweeps and intervals its samples cover. A sample
  // that is not finite, saturated or out of order is dropped and counted (imuDroppedCounts()).
  void addImu(const ImuSample& sample) { imu_.add(sample); }
  // The IMU's mount in the LiDAR frame, as imu.position (m) and imu.rotation_deg (roll, pitch, yaw) give
  // it, in place of the configuration's: for a mount known only once running (the ROS node's, from TF).
  // config() says it from then on.
  void setImuMount(const std::vector<double>& position, const std::vector<double>& rotation_deg);
  // Hands over the scan a later process() call will be given, normally the call after the next one, so
  // that a device backend uploads it while the next call processes its scan (Backend::prefetch(),
  // docs/cuda.md). Only a speed-up: process() gives the same results, bit for bit, whatever was
  // prefetched, and takes the upload for the same cloud only (the same arrays' memory and lengths, and the
  // same stamp; a cloud moved to another PointCloud is the same). `cloud` must stay alive until the next
  // process() call returns, and must not change until it is processed.
  void prefetch(const PointCloud& cloud) { backend_->prefetch(cloud); }

  // Forgets the model, the motion and the pose: the next scan starts a new trajectory at identity.
  void reset();

  // The sensor's pose at the latest processed scan's stamp (FrameResult::pose).
  const Eigen::Isometry3d& pose() const { return pose_; }
  // The sensor's pose at the latest processed scan's reference instant: the frame the model and the
  // scan's deskewed points live in (Backend::model(), Backend::scan()). Mid-sweep for `field` times
  // (CloudTimes::reference); pose() for the other time sources.
  Eigen::Isometry3d modelPose() const { return pose_ * stamp_in_reference_.inverse(); }
  const Config& config() const { return config_; }
  Backend& backend() { return *backend_; }
  const Backend& backend() const { return *backend_; }
  // Why the odometry runs on another backend than runtime.backend asked for (runtime.backend_fallback);
  // empty when it runs on that one.
  const std::string& backendWarning() const { return backend_warning_; }
  size_t processedCount() const { return processed_; }
  const std::map<std::string, size_t>& skippedCounts() const { return skipped_; }
  // Scans registered with at least one degenerate direction (RegistrationResult::degeneracy).
  size_t degenerateCount() const { return degenerate_; }
  // Scans whose per-point times were not used, or not all used, by FrameResult::time_warning.
  const std::map<std::string, size_t>& timeWarningCounts() const { return time_warnings_; }
  // Scans with a FrameResult::sensor_warning.
  size_t sensorMisfitCount() const { return sensor_misfits_; }
  // Start searches run (FrameResult::start_search), and those whose winner did not stand out.
  size_t startSearchCount() const { return start_searches_; }
  // Scans after a gap shorter than model.time_window, their motion searched (FrameResult::gap).
  size_t gapCount() const { return gaps_; }
  size_t ambiguousStartCount() const { return ambiguous_starts_; }
  // Tracking health: refused registrations by reason, recoveries after them, model restarts after
  // motion.restart_after refusals in a row, and whether the latest registration was refused (lost).
  const std::map<std::string, size_t>& refusalCounts() const { return refusals_; }
  size_t recoveryCount() const { return recoveries_; }
  size_t trackingRestartCount() const { return tracking_restarts_; }
  // The sensor's height above the ground the scans show (median of recent checks); nullopt before any.
  std::optional<double> measuredSensorHeight() const { return height_check_.measured(); }
  bool lost() const { return refused_in_row_ > 0; }
  // With imu.enabled: the scans the gyro could not turn, by FrameResult::imu_fallback, and the samples
  // dropped, by reason.
  const std::map<std::string, size_t>& imuFallbackCounts() const { return imu_fallbacks_; }
  const std::map<std::string, size_t>& imuDroppedCounts() const { return imu_.droppedCounts(); }
  // With imu.accelerometer: the intervals whose specific force the inertial filter did not take, their
  // translation missing the registered one (imu.accel_gate).
  size_t accelGatedCount() const { return accel_gated_; }
  // The IMU's state in one struct, for the node's diagnostics.
  ImuStatus imuStatus() const;
  // With imu.accelerometer: gravity in the odometry's world frame (the first scan's), the IMU's velocity
  // and the accelerometers' bias as estimated so far (InertialFilter; started() once a scan was registered).
  const InertialFilter& inertialState() const { return inertial_; }

  // A scan filling fewer pixels of its range image than three full rows (normals.min_window_height rows
  // of sensor.image_width) is skipped as "too few valid points". It cannot give surface normals over
  // any real extent: a blocked or failing sensor, one ring, a fraction of a sweep. Registered anyway,
  // such scans threw the pose off by metres with registration.degeneracy_threshold 0, by centimetres
  // with the default (test/core/test_fault_cases.cpp). Healthy sweeps fill 57-78% of the image in every
  // simulated world: 3 (VLP-16) to 17 (HDL-64E) times this.
  size_t minOccupiedPixels() const;

 private:
  // process() but for the total time and the end of the prefetch.
  FrameResult processScan(const PointCloud& cloud);
  FrameResult skip(const std::string& reason);
  // SensorFit::warning() of about kSensorFitSamples of the cloud's points, counted when not empty.
  std::string sensorWarning(const PointCloud& cloud);
  // Forgets the model and the motion but keeps the pose: the next scan continues the trajectory from it.
  void restartModel();
  // `stamp` - the first scan's stamp, in whole nanoseconds as ROS stamps count time. The intervals the
  // motion prior and the model's time window see are differences of these: so a drive stamped from 0
  // (times.txt) and the same drive stamped from a later start (a bag's ros::Time stamps) give the same
  // intervals to the bit, and the same poses, where the raw differences would differ in their last bits.
  double secondsSinceFirst(double stamp) const;
  // Resets or restarts when `stamp` breaks the timeline (see process()), saying so in `result`.
  void followTimeline(double stamp, FrameResult& result);
  // Whether a registration ended farther from its guess than five robust-kernel scales (0.5 m by default),
  // a turn counted as the move it makes 10 m away: the motion prior overshot (a swing's peak, a fall back
  // to the LiDAR's prior), and the next scan's registration, started from a prior as far off, is not
  // informed: a loose kernel first and no direction held to the prior (registration.hpp). Informed, it
  // converged near the overshoot, within the bounds, and the track was lost.
  bool priorMissed(const Eigen::Isometry3d& guess, const Eigen::Isometry3d& registered) const;
  // Registers the projected scan from `guess`. After each Gauss-Newton step under the final kernel, up to
  // deskew.rounds times, it deskews the scan again under the motion estimated so far and lets the
  // iterations go on, when that changes the deskew by more than a converged step over the sweep
  // (`farthest` seconds either side of the reference; changesRegistration()): a round after the first
  // step, when the estimate is already close, costs no iterations of its own, where a round after
  // convergence cost about three to converge again. Against a provisional model the scan is deskewed
  // once, for the model, after the registration converges (docs/deskew.md).
  // `deskewed`: the velocity the projection deskewed the scan under; returns the one it ends deskewed
  // under. The registration is between the scans' reference instants (CloudTimes::reference), `dt` apart.
  // `informed`: the guess is the motion prior's, with enough history to trust (MotionModel::informed()).
  Vector6d registerAndDeskew(const Eigen::Isometry3d& guess, bool informed, double dt, const Vector6d& deskewed,
                             double farthest, FrameResult& result);
  // The registration from the motion prior was refused (a swing the prior could not follow): the scan,
  // deskewed as it was projected (`projected_under`) again, has its motion searched as at a start and
  // is registered from the winner; `result.refusal` becomes that registration's. Returns the velocity the
  // scan ends deskewed under.
  Vector6d searchAfterRefusal(double dt, const Vector6d& projected_under, const Vector6d& deskewed_under,
                              double farthest, FrameResult& result);
  // Whether the scan `since_first` seconds after the first follows a gap (FrameResult::gap): then neither
  // the motion prior nor what the tracking guard holds registrations against (velocity, inliers) holds.
  void followGap(double since_first, FrameResult& result);
  // The interval the scans come at: the sensor's period, or the longer one between the scan before and
  // the one before it (a throttled topic).
  double usualScanInterval() const;
  bool afterGap() const { return interval_before_gap_ > 0.0; }
  // The registration's initial guess: the motion prior's prediction, or where the start search puts the
  // scan when no motion is known yet (recorded in `result`).
  Eigen::Isometry3d initialGuess(double dt, FrameResult& result);
  // The start search (start_search.hpp) for a scan whose motion is unknown: around the motion accepted
  // last carried over `dt` when a refusal made the motion unknown (its reach along x spans a vehicle that
  // stopped as well as one that drove on); around the identity at a start, when none was accepted; after a
  // gap, around that motion and the one of the usual scan interval too (a clock that jumped). With the gyro's
  // rotation over the interval, every candidate takes it and only translations are searched. Recorded in
  // `result.start_search` and counted.
  void searchMotion(double dt, FrameResult& result);
  // The velocity a scan is deskewed under before it is registered: the last registered (the motion
  // prior's), or after a refusal the one accepted last; zero at a start and without a motion prior.
  Vector6d sweepVelocityBeforeRegistration() const;
  // Projects the cloud deskewed under `velocity`, turned by the gyro's rotation through the sweep when it
  // is known; when that fills too few pixels (a wrong velocity moves the points out of the image),
  // projects it again as measured (deskewed again, if at all, at the velocity's rate), saying so in
  // `result`: a scan is then
  // skipped for what it is, never for the odometry's own velocity. Returns the occupied pixels.
  size_t projectDeskewed(const PointCloud& cloud, float stamp, const CloudTimes& times, Vector6d& velocity,
                         FrameResult& result);
  // Takes the scan's registration `reference_delta` (over `dt`, the scan deskewed under `deskewed_under`):
  // the pose, the motion prior and the tracking guard move on. Returns the scan's stamp frame in its
  // reference frame.
  Eigen::Isometry3d acceptRegistration(const Eigen::Isometry3d& reference_delta, double dt,
                                       const Vector6d& deskewed_under, const CloudTimes& times, FrameResult& result);
  // Refuses the scan's registration (result.refusal): its pose is the last accepted velocity carried over
  // `dt`, the motion becomes unknown (the next scan searches it). Returns true when the refusals in a row
  // reached motion.restart_after: the model has been restarted at that pose, for the scan to start anew.
  bool refuseRegistration(double dt, FrameResult& result);
  // What the gyro says of the scan stamped `stamp` (imu.enabled): its rotation since the last accepted
  // scan, between their reference instants, and its mean rate over the sweep; a fallback is counted and
  // put in `result`. Nothing without imu.enabled.
  GyroMotion gyroMotion(double stamp, const CloudTimes& times, FrameResult& result);
  // The IMU's motion between the last accepted scan's reference instant and this scan's (imu.accelerometer;
  // samples covering it, as the gyro's), into inertial_interval_; whether it is known.
  bool preintegrateInterval(double previous_reference, double reference);
  // Whether the accelerometers give this scan's translation: the IMU covered its interval and the inertial
  // filter's velocity is known.
  bool inertialPriorKnown() const { return inertial_interval_known_ && inertial_.ready(); }
  // The scan's translation since the last accepted one by the accelerometers (inertialPriorKnown()).
  Eigen::Vector3d inertialTranslation() const {
    return inertial_.predictTranslation(inertial_interval_, modelPose().linear(), gyro_.rotation);
  }
  // The accepted registration `reference_delta` corrects the inertial filter, which moves on to this scan
  // (its velocity forgotten when the IMU did not cover the interval), and roll and pitch are held to
  // gravity (holdTilt()). `attitude`: the last accepted scan's reference frame in the world;
  // `reference_time`: this scan's reference instant, s since the first scan. After acceptRegistration().
  void followInertial(const Eigen::Matrix3d& attitude, const Eigen::Isometry3d& reference_delta, double reference_time);
  // Roll and pitch turned towards gravity past imu.tilt_hold_deg (TiltHold), the filter's world with them.
  // `force`: the interval's specific force in the world (InertialFilter::worldForce()), when the IMU
  // covered it.
  void holdTilt(const std::optional<Eigen::Vector3d>& force, double reference_time);
  // `velocity` (a sweep's twist per second) turning at the gyro's rate over the scan's sweep, when known.
  Vector6d withGyroRate(Vector6d velocity) const;
  // One round: the scan deskewed again in place under `velocity`, its ground map rebuilt, timed in `result`.
  void deskewScanAgain(const Vector6d& velocity, FrameResult& result);
  // Sec. III-C: ground segmentation, normals and the BEV ground map of the projected scan.
  void extractFeatures();
  // The second scan of a start, registered against the first as both were measured (model_provisional_):
  // both deskewed under the motion found, the first made the model again, the second registered against
  // it. Returns the velocity the two scans' stamps are placed under (acceptRegistration()): the one the
  // deskewed scans registered.
  Vector6d registerAgainstDeskewedStart(const PointCloud& cloud, float stamp, const CloudTimes& times, double dt,
                                        const Vector6d& velocity, FrameResult& result);
  // The first scan of a start had no velocity to place its stamp in its sweep (stamp_in_reference_): its
  // translation under `velocity`, the motion the next scan registered, and its turn too unless the gyro
  // turned it.
  void placeFirstStamp(const Vector6d& velocity);

  Config config_;
  std::unique_ptr<Backend> backend_;
  std::string backend_warning_;
  MotionModel motion_;
  Eigen::Isometry3d pose_ = Eigen::Isometry3d::Identity();  // at the latest scan's stamp
  // Scans are registered, and the model and motion prior kept, at each scan's reference instant (mid-sweep;
  // CloudTimes::reference): the latest scan's stamp frame in its reference frame, and that reference's
  // offset from the stamp (s). Identity and 0 unless the scan had `field` times.
  Eigen::Isometry3d stamp_in_reference_ = Eigen::Isometry3d::Identity();
  double last_reference_ = 0.0;
  bool started_ = false;
  // The model holds only the first scan of a start, which had per-point times but no motion to deskew
  // them with. Fused, its distorted points would stay (the oldest point on a surface does) and bias the
  // registrations of the next model.time_window seconds: the next scan, registered against it as measured,
  // tells the motion, and the first scan deskewed under it becomes the model instead
  // (registerAgainstDeskewedStart()); a registration that did not converge replaces it with its own scan.
  bool model_provisional_ = false;
  // The provisional model's scan as measured, how it was projected, and its relative stamp.
  PointCloud provisional_cloud_;
  SweepMotion provisional_motion_;
  float provisional_stamp_ = 0.0f;
  // That first scan was turned by the gyro at each point's time: the turn between its stamp and its
  // reference instant is the gyro's (in stamp_in_reference_), not the next scan's rate, which misses it by
  // degrees when a sweep is swung at a changing rate (a start mid-swing).
  bool provisional_turned_by_gyro_ = false;
  double first_stamp_ = 0.0;
  double last_stamp_ = 0.0;
  double last_since_first_ = 0.0;  // secondsSinceFirst(last_stamp_)
  double previous_scan_since_first_ = 0.0;  // of the scan before, registered or refused
  double usual_scan_interval_ = 0.0;        // between the scan before and the one before it; 0 at a start
  size_t processed_ = 0;
  size_t degenerate_ = 0;
  std::map<std::string, size_t> skipped_;
  std::map<std::string, size_t> time_warnings_;
  size_t sensor_misfits_ = 0;
  size_t start_searches_ = 0;
  size_t ambiguous_starts_ = 0;
  size_t gaps_ = 0;
  TrackingGuard guard_;
  SensorHeightCheck height_check_;
  // The velocity of the last accepted registration (twist per second), which carries refused scans; kept
  // when the motion becomes unknown for the search.
  Vector6d held_velocity_ = Vector6d::Zero();
  // The last accepted registration ended far from its guess (priorMissed()): the next is not informed.
  bool prior_missed_ = false;
  std::map<std::string, size_t> refusals_;
  size_t refused_in_row_ = 0;
  size_t recoveries_ = 0;
  size_t tracking_restarts_ = 0;
  ImuTrack imu_;
  GyroMotion gyro_;  // of the scan being processed
  // The usual scan interval before the gap the scan being processed follows (FrameResult::gap); 0: none.
  double interval_before_gap_ = 0.0;
  InertialFilter inertial_;
  TiltHold tilt_hold_;
  Preintegration inertial_interval_;  // of the scan being processed, since the last accepted one
  bool inertial_interval_known_ = false;
  // The LiDAR-only prior's translation for the scan being processed, when the motion model had one: the
  // accelerometers' gate measures their miss against its.
  std::optional<Eigen::Vector3d> lidar_prior_translation_;
  size_t accel_gated_ = 0;
  std::map<std::string, size_t> imu_fallbacks_;
};

}  // namespace elo
