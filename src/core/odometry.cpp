#include "elo/pipeline/odometry.hpp"

#include <algorithm>
#include <cmath>
#include <utility>
#include <vector>

#include "core/elapsed_time.hpp"
#include "elo/pipeline/deskew.hpp"
#include "elo/se3.hpp"
#include "elo/sensor/sensor_fit.hpp"

namespace elo {

Odometry::Odometry(const Config& config)
    : config_(config),
      motion_(config.model.motion_prior),
      guard_(config),
      height_check_(config.ground.sensor_height),
      imu_(config.imu),
      inertial_(config.imu),
      tilt_hold_(config.imu) {
  validate(config_);
  backend_ = makeBackend(config_, &backend_warning_);
}

void Odometry::restartModel() {
  backend_->resetModel();
  motion_.reset();
  guard_.reset();
  held_velocity_.setZero();
  prior_missed_ = false;
  refused_in_row_ = 0;
  started_ = false;
}

bool Odometry::priorMissed(const Eigen::Isometry3d& guess, const Eigen::Isometry3d& registered) const {
  constexpr double kLever = 10.0;  // m
  // At 3 scales the swung VLP-16 sweeps under a car's bounds were lost further (t_rel 295 % against 102 %)
  // and a simulated car drive with miscalibrated beams changed its poses; at 5, no car drive measured did.
  constexpr double kKernelScales = 5.0;
  const Eigen::Isometry3d miss = guess.inverse() * registered;
  return miss.translation().norm() + kLever * rotationAngle(miss) >
         kKernelScales * config_.registration.robust_kernel_scale;
}

void Odometry::reset() {
  restartModel();
  inertial_.reset();
  tilt_hold_.reset();
  pose_ = Eigen::Isometry3d::Identity();
  stamp_in_reference_ = Eigen::Isometry3d::Identity();
}

void Odometry::followTimeline(double stamp, FrameResult& result) {
  if (!started_) return;
  if (stamp < last_stamp_) {
    // A bag played in a loop, or a clock jump: the old model and motion describe another time.
    reset();
    result.reset = true;
  } else if (stamp - last_stamp_ > config_.model.time_window) {
    // Every model point is older than tau_w, and no motion prior holds for that long: registering
    // against the stale model from an extrapolated guess could converge anywhere. Carry on from the
    // last pose with a new model instead; the pose does not jump, and the caller is told.
    restartModel();
    result.gap_restart = true;
  }
}

double Odometry::usualScanInterval() const {
  return std::max(1.0 / config_.sensor.rotation_rate_hz, usual_scan_interval_);
}

void Odometry::followGap(double since_first, FrameResult& result) {
  // From the scan before, refused or not: refusals in a row leave the registration's interval long, and
  // are not a gap.
  const double interval = since_first - previous_scan_since_first_;
  previous_scan_since_first_ = since_first;
  // Against the scans' own pace: a topic throttled to every third scan, or a run with --stride 3, has no
  // gap at each scan. The first interval after a start sets it.
  const double usual = usualScanInterval();
  const bool gap = started_ && config_.start_search.enabled && usual_scan_interval_ > 0.0 &&
                   interval > config_.start_search.after_gap_periods * usual;
  interval_before_gap_ = gap ? usual : 0.0;
  usual_scan_interval_ = started_ ? interval : 0.0;
  if (!gap) return;
  // Scans were dropped, or the clock jumped forward: the sensor may have turned, stopped or moved a single
  // scan period's worth, and a registration from the velocity carried over the gap converged metres off
  // (a 0.3 s jump at 10 m/s: 3 m, accepted). The motion is searched instead, and is held against neither
  // the velocity from before the gap nor the inliers: the model seen from 31 m on after a 3 s gap at
  // 10 m/s gives a quarter of them, a collapse to the guard, which refused the scans after the gap until
  // the model restarted.
  motion_.reset();
  guard_.reset();
  result.gap = interval;
  ++gaps_;
}

double Odometry::secondsSinceFirst(double stamp) const { return std::round((stamp - first_stamp_) * 1e9) / 1e9; }

size_t Odometry::minOccupiedPixels() const {
  return static_cast<size_t>(config_.normals.min_window_height) * static_cast<size_t>(config_.sensor.image_width);
}

// Enough points for a share to about a percent against the 5% threshold, in about 8 us a scan: 2% of
// the CUDA backend's time for an HDL-64E scan.
constexpr size_t kSensorFitSamples = 512;

std::string Odometry::sensorWarning(const PointCloud& cloud) {
  const size_t stride = cloud.points.size() > kSensorFitSamples ? cloud.points.size() / kSensorFitSamples : 1;
  std::string warning = checkSensorFit(cloud, config_.sensor, stride).warning(config_.sensor);
  if (!warning.empty()) ++sensor_misfits_;
  return warning;
}

// The sensor height is checked on each of the first scans, then on every 20th: a mount does not move,
// but a warning at the start must not wait.
constexpr size_t kSensorHeightChecksAtStart = 5;
constexpr size_t kSensorHeightCheckPeriod = 20;

FrameResult Odometry::skip(const std::string& reason) {
  ++skipped_[reason];
  FrameResult result;
  result.skip_reason = reason;
  result.pose = pose_;
  return result;
}

void Odometry::deskewScanAgain(const Vector6d& velocity, FrameResult& result) {
  const auto deskew_start = Clock::now();
  backend_->deskewScan(velocity);
  backend_->buildGroundMap();
  backend_->synchronize();
  result.times.deskew += millisecondsSince(deskew_start);
  ++result.deskew_rounds;
}

Vector6d Odometry::registerAndDeskew(const Eigen::Isometry3d& guess, bool informed, double dt,
                                     const Vector6d& deskewed, double farthest, FrameResult& result) {
  Vector6d deskewed_under = deskewed;
  const ScanRefresh deskew_again = [&](const Eigen::Isometry3d& estimate, bool converged) {
    // Across a gap the registered motion tells no sweep velocity (see acceptRegistration()).
    if (result.time_source == TimeSource::none || afterGap()) return false;
    // Against a model of the first scan as measured, the scan as measured registers best (the two are
    // bent alike): it is deskewed once, whatever deskew.rounds says, when the registration has converged,
    // only to replace that model.
    if (model_provisional_ && !converged) return false;
    const int rounds = model_provisional_ ? 1 : config_.deskew.rounds;
    const Vector6d velocity = withGyroRate(sweepVelocity(estimate, dt));
    if (result.deskew_rounds >= rounds || !changesRegistration(deskewed_under, velocity, farthest, config_.registration)) {
      return false;
    }
    deskewScanAgain(velocity, result);
    deskewed_under = velocity;
    return !model_provisional_;
  };
  const auto stage_start = Clock::now();
  const double deskew_before = result.times.deskew;
  result.registration = registerScan(*backend_, guess, informed, config_.registration, deskew_again);
  result.times.registration += millisecondsSince(stage_start) - (result.times.deskew - deskew_before);
  return deskewed_under;
}

Eigen::Isometry3d Odometry::initialGuess(double dt, FrameResult& result) {
  Eigen::Isometry3d guess;
  if (motion_.known() || !config_.start_search.enabled) {
    guess = motion_.predict(dt);
  } else {
    searchMotion(dt, result);
    guess = result.start_search.motion;
  }
  lidar_prior_translation_.reset();
  if (motion_.known()) lidar_prior_translation_ = guess.translation();
  if (gyro_.known) guess.linear() = gyro_.rotation;
  if (motion_.known() && inertialPriorKnown()) {
    guess.translation() = inertialTranslation();
  }
  return guess;
}

bool Odometry::preintegrateInterval(double previous_reference, double reference) {
  if (!config_.imu.accelerometer || !started_) return false;
  return imu_.preintegrate(previous_reference, reference, inertial_interval_).empty();
}

void Odometry::followInertial(const Eigen::Matrix3d& attitude, const Eigen::Isometry3d& reference_delta,
                              double reference_time) {
  if (!config_.imu.accelerometer) return;
  std::optional<Eigen::Vector3d> force;
  if (gyro_.known && inertial_interval_known_) {
    if (!inertial_.update(inertial_interval_, attitude, reference_delta, lidar_prior_translation_)) ++accel_gated_;
    force = inertial_.worldForce(inertial_interval_, attitude);
  } else {
    inertial_.forgetVelocity();
  }
  holdTilt(force, reference_time);
}

void Odometry::holdTilt(const std::optional<Eigen::Vector3d>& force, double reference_time) {
  const Eigen::Vector3d imu_position = modelPose() * Eigen::Map<const Eigen::Vector3d>(config_.imu.position.data());
  const Eigen::Matrix3d turn = tilt_hold_.follow(reference_time, imu_position, force);
  if (turn.isIdentity(0.0)) return;
  pose_.linear() = turn * pose_.linear();
  inertial_.turnWorld(turn);
}

GyroMotion Odometry::gyroMotion(double stamp, const CloudTimes& times, FrameResult& result) {
  if (!config_.imu.enabled) return {};
  const double reference = stamp + times.reference;
  const double half_sweep = 0.5 / config_.sensor.rotation_rate_hz;
  const double previous_reference = started_ ? last_stamp_ + last_reference_ : reference;
  GyroMotion gyro =
      imu_.scanMotion(previous_reference, reference, reference - half_sweep, reference + half_sweep, stamp);
  inertial_interval_known_ = gyro.known && preintegrateInterval(previous_reference, reference);
  if (!gyro.fallback.empty()) ++imu_fallbacks_[gyro.fallback];
  result.imu_fallback = gyro.fallback;
  imu_.forgetBefore(previous_reference - half_sweep);
  return gyro;
}

void Odometry::setImuMount(const std::vector<double>& position, const std::vector<double>& rotation_deg) {
  Config mounted = config_;
  mounted.imu.position = position;
  mounted.imu.rotation_deg = rotation_deg;
  validate(mounted);
  config_ = std::move(mounted);
  imu_.setMount(config_.imu);
  inertial_.setMount(config_.imu);
  tilt_hold_.reset();
}

ImuStatus Odometry::imuStatus() const {
  ImuStatus status;
  status.samples_taken = imu_.takenCount();
  status.dropped = imu_.droppedCounts();
  status.fallbacks = imu_fallbacks_;
  status.gyro_bias = imu_.biasEstimate();
  status.gravity_known = inertial_.started();
  status.gravity = inertial_.gravity();
  status.accel_bias = imu_.accelBiasSet() + inertial_.learntBias();
  status.accel_gated = accel_gated_;
  status.tilt_deg = tilt_hold_.tiltDeg();
  status.tilt_held = tilt_hold_.heldCount();
  return status;
}

Vector6d Odometry::withGyroRate(Vector6d velocity) const {
  if (gyro_.known) velocity.tail<3>() = gyro_.sweep_rate;
  return velocity;
}

size_t Odometry::projectDeskewed(const PointCloud& cloud, float stamp, const CloudTimes& times, Vector6d& velocity,
                                 FrameResult& result) {
  // With the gyro, each point turned by its rotation at the point's own time (the velocity's rate serves
  // the translation's own turn only).
  const size_t occupied = backend_->projectScan(cloud, stamp, {times.source, velocity, times.reference, gyro_.sweep});
  if (occupied >= minOccupiedPixels() || (velocity.isZero() && !gyro_.sweep.known())) return occupied;
  velocity.setZero();
  result.projected_without_deskew = true;
  return backend_->projectScan(cloud, stamp, {times.source, velocity, times.reference, {}});
}

Eigen::Isometry3d Odometry::acceptRegistration(const Eigen::Isometry3d& reference_delta, double dt,
                                               const Vector6d& deskewed_under, const CloudTimes& times,
                                               FrameResult& result) {
  // Under the velocity the points were moved with, the sensor at the stamp (time 0, `reference` seconds
  // before the reference instant) is exp(-reference * velocity) in the reference frame.
  Eigen::Isometry3d stamp_in_reference = expSE3(-times.reference * deskewed_under);
  // With a gyro, the turn it measured between the two instants: the velocity's rate is its mean over the
  // sweep, which the stamp at one end of a sweep swung at a changing rate would miss by up to a degree.
  if (gyro_.known) stamp_in_reference.linear() = gyro_.stamp_rotation;
  // The first scan of a start had no velocity to place its stamp in its sweep; registered against it as
  // measured (bent alike), this scan measured the motion between like instants of the two sweeps. Turned
  // by the gyro, its stamp's turn is the one the gyro measured over its own sweep.
  if (model_provisional_) placeFirstStamp(deskewed_under);
  // T^{t-1}_t between the stamps; exactly the reference delta when both references are the stamps.
  result.delta = stamp_in_reference_.inverse() * reference_delta * stamp_in_reference;
  pose_ = pose_ * result.delta;
  const Degeneracy& degeneracy = result.registration.degeneracy;
  if (degeneracy.any()) ++degenerate_;
  guard_.accept(result.registration, dt);
  if (afterGap()) {
    // The motion across a gap tells no velocity (over a clock that jumped, a fraction of the true one):
    // the next scan is searched around the velocity from before the gap, and its registration gives the
    // velocity anew.
    guard_.forgetVelocity();
  } else {
    motion_.record(reference_delta, dt);
    motion_.holdVelocityAlong(degeneracy.priorShare());
    held_velocity_ = motion_.latestVelocity();
  }
  if (refused_in_row_ > 0) {
    result.recovered = true;
    ++recoveries_;
    refused_in_row_ = 0;
  }
  return stamp_in_reference;
}

void Odometry::extractFeatures() {
  backend_->segmentGround();
  backend_->estimateNormals();
  backend_->buildGroundMap();
  backend_->synchronize();  // a device backend's stages run on after the calls return
}

Vector6d Odometry::registerAgainstDeskewedStart(const PointCloud& cloud, float stamp, const CloudTimes& times,
                                               double dt, const Vector6d& velocity, FrameResult& result) {
  const auto rebuild_start = Clock::now();
  // The start's first scan, deskewed now that the motion is known, becomes the model in place of the
  // scan as measured.
  backend_->resetModel();
  SweepMotion first_motion = provisional_motion_;
  first_motion.velocity = velocity;
  if (backend_->projectScan(provisional_cloud_, provisional_stamp_, first_motion) < minOccupiedPixels()) {
    // Deskewed out of its image (a motion beyond any vehicle's, with the motion bounds off): as measured,
    // as projectDeskewed() falls back for this scan.
    backend_->projectScan(provisional_cloud_, provisional_stamp_, provisional_motion_);
  }
  extractFeatures();
  backend_->updateModel(Eigen::Isometry3d::Identity(), provisional_stamp_);
  model_provisional_ = false;
  // This scan, deskewed under the same motion, registered against it from where the two bent scans met.
  Vector6d deskewed_under = velocity;
  projectDeskewed(cloud, stamp, times, deskewed_under, result);
  extractFeatures();
  result.times.deskew += millisecondsSince(rebuild_start);
  registerAndDeskew(result.registration.model_from_scan, false, dt, deskewed_under, times.farthest, result);
  // The motion the two deskewed scans tell is finer than the bent scans' (8 mm in 0.1 s on a street at
  // 10 m/s), too little to deskew them again but not to place a stamp half a sweep from its reference:
  // both scans' stamps are placed under it, as the next scan's will be under the motion prior's.
  const Vector6d refined = withGyroRate(sweepVelocity(result.registration.model_from_scan, dt));
  placeFirstStamp(refined);
  return refined;
}

void Odometry::placeFirstStamp(const Vector6d& velocity) {
  const Eigen::Isometry3d under_velocity = expSE3(-last_reference_ * velocity);
  if (!provisional_turned_by_gyro_) stamp_in_reference_.linear() = under_velocity.linear();
  stamp_in_reference_.translation() = under_velocity.translation();
}

Vector6d Odometry::searchAfterRefusal(double dt, const Vector6d& projected_under, const Vector6d& deskewed_under,
                                      double farthest, FrameResult& result) {
  // The refused registration's motion may have deskewed the scan: back to how it was projected.
  if (deskewed_under != projected_under) deskewScanAgain(projected_under, result);
  result.deskew_rounds = 0;
  searchMotion(dt, result);
  const Vector6d searched_under =
      registerAndDeskew(result.start_search.motion, false, dt, projected_under, farthest, result);
  result.refusal = guard_.refusal(result.registration, dt);
  return searched_under;
}

bool Odometry::refuseRegistration(double dt, FrameResult& result) {
  ++refusals_[result.refusal];
  ++refused_in_row_;
  result.delta = expSE3(held_velocity_ * dt);
  if (gyro_.known) result.delta.linear() = gyro_.rotation;
  if (inertialPriorKnown()) {
    result.delta.translation() = inertialTranslation();
  }
  result.pose = pose_ * result.delta;
  motion_.reset();
  // The registrations the filter's velocity came from may have led it astray, as they did the prior:
  // it is measured again from the registrations that follow, as the LiDAR's motion is.
  if (config_.imu.enabled) inertial_.forgetVelocity();
  if (refused_in_row_ < static_cast<size_t>(config_.motion.restart_after)) return false;
  // The model no longer matches what the sensor sees: start again from this scan, where the prior puts it.
  const Vector6d held = held_velocity_;
  restartModel();
  held_velocity_ = held;
  pose_ = result.pose;
  stamp_in_reference_ = Eigen::Isometry3d::Identity();
  result.tracking_restart = true;
  ++tracking_restarts_;
  return true;
}

void Odometry::searchMotion(double dt, FrameResult& result) {
  std::vector<SearchLine> lines{{expSE3(held_velocity_ * dt), dt}};
  if (afterGap()) lines.push_back({expSE3(held_velocity_ * interval_before_gap_), interval_before_gap_});
  // With the gyro's rotation over the interval every candidate takes it: a sensor turning fast at a start
  // (a handheld rig started mid-swing) is found by translations alone.
  if (gyro_.known) {
    for (SearchLine& line : lines) line.centre.linear() = gyro_.rotation;
  }
  result.start_search = searchStartMotion(*backend_, lines, config_,
                                          gyro_.known ? StartRotation::from_gyro : StartRotation::search_yaw);
  ++start_searches_;
  if (result.start_search.ambiguous) ++ambiguous_starts_;
}

Vector6d Odometry::sweepVelocityBeforeRegistration() const {
  if (config_.model.motion_prior == MotionPrior::none) return Vector6d::Zero();
  return motion_.known() ? motion_.velocity() : held_velocity_;
}

FrameResult Odometry::process(const PointCloud& cloud) {
  const auto start = Clock::now();
  FrameResult result;
  try {
    result = processScan(cloud);
  } catch (...) {
    backend_->finishPrefetch();  // the caller may free the prefetched cloud once this returns
    throw;
  }
  // Normally staged long before; a wait here is the pipeline's, and counts in its time.
  backend_->finishPrefetch();
  if (result.processed) result.times.total = millisecondsSince(start);
  return result;
}

FrameResult Odometry::processScan(const PointCloud& cloud) {
  if (cloud.points.empty()) return skip("empty cloud");
  if (!std::isfinite(cloud.stamp)) return skip("stamp not finite");
  if (started_ && secondsSinceFirst(cloud.stamp) == last_since_first_) return skip("duplicate stamp");
  FrameResult result;
  followTimeline(cloud.stamp, result);
  if (!started_) first_stamp_ = cloud.stamp;
  // A start, or a model restarted after a gap: the interval to this scan has no registration to carry
  // the inertial filter's velocity over. Gravity and the bias stay, as the world frame does.
  if (!started_ && config_.imu.enabled) inertial_.forgetVelocity();
  const double since_first = secondsSinceFirst(cloud.stamp);

  // Observation times are kept relative to the first scan: a float holds them to a millisecond for hours.
  const float relative_stamp = static_cast<float>(since_first);
  const CloudTimes times = inspectTimes(cloud, config_);
  result.time_source = times.source;
  result.time_warning = times.warning;
  result.points_without_time = times.outside_sweep;
  if (!times.warning.empty()) ++time_warnings_[times.warning];
  result.sensor_warning = sensorWarning(cloud);
  // Each of the first scans, then every kSensorHeightCheckPeriod-th: about 0.3 ms a check.
  if (processed_ < kSensorHeightChecksAtStart || processed_ % kSensorHeightCheckPeriod == 0) {
    result.sensor_height_warning = height_check_.add(cloud);
  }
  // The motion is estimated between the scans' reference instants: the stamps' interval, moved by how the
  // references lie within their sweeps (0 but for `field` times).
  const double stamp_interval = since_first - last_since_first_ + (times.reference - last_reference_);
  const double dt = started_ ? motionInterval(stamp_interval, times.source, config_.sensor) : 0.0;
  followGap(since_first, result);

  gyro_ = gyroMotion(cloud.stamp, times, result);
  auto stage_start = Clock::now();
  // Deskewed under the velocity last registered: the first scans (none yet) as they were measured. With an
  // IMU, turned by the gyro's rotation through the sweep.
  Vector6d sweep_velocity = withGyroRate(started_ ? sweepVelocityBeforeRegistration() : Vector6d::Zero());
  const size_t occupied = projectDeskewed(cloud, relative_stamp, times, sweep_velocity, result);
  result.times.projection = millisecondsSince(stage_start);
  if (occupied < minOccupiedPixels()) {
    FrameResult skipped = skip("too few valid points");
    skipped.reset = result.reset;
    skipped.gap_restart = result.gap_restart;
    skipped.time_warning = result.time_warning;
    skipped.sensor_warning = result.sensor_warning;
    skipped.sensor_height_warning = result.sensor_height_warning;
    return skipped;
  }

  stage_start = Clock::now();
  extractFeatures();
  result.times.feature_extraction = millisecondsSince(stage_start);

  // The scan's frame at its reference instant, relative to the last scan's; and its stamp's frame in it.
  Eigen::Isometry3d reference_delta = Eigen::Isometry3d::Identity();
  Eigen::Isometry3d stamp_in_reference = Eigen::Isometry3d::Identity();
  if (started_) {
    const Eigen::Isometry3d guess = initialGuess(dt, result);
    Vector6d deskewed_under =
        registerAndDeskew(guess, motion_.informed() && !prior_missed_, dt, sweep_velocity, times.farthest, result);
    // The start's first two scans met bent alike; their motion known, both are deskewed and met again.
    if (model_provisional_ && result.registration.converged && !result.registration.failed) {
      deskewed_under = registerAgainstDeskewedStart(cloud, relative_stamp, times, dt, deskewed_under, result);
    }
    result.refusal = guard_.refusal(result.registration, dt);
    if (!result.refusal.empty() && !result.start_search.searched && config_.start_search.enabled) {
      deskewed_under = searchAfterRefusal(dt, sweep_velocity, deskewed_under, times.farthest, result);
    }
    result.times.registration += result.start_search.milliseconds;
    if (!result.refusal.empty()) {
      const bool restarted = refuseRegistration(dt, result);
      if (!restarted) {
        ++processed_;
        result.processed = true;
        return result;
      }
    } else {
      reference_delta = result.registration.model_from_scan;
      const Eigen::Matrix3d attitude_before = modelPose().linear();
      stamp_in_reference = acceptRegistration(reference_delta, dt, deskewed_under, times, result);
      prior_missed_ = priorMissed(guess, reference_delta);
      if (config_.imu.enabled) followInertial(attitude_before, reference_delta, since_first + times.reference);
      if (gyro_.known && result.registration.converged && !result.registration.degeneracy.any()) {
        imu_.learnBias(gyro_.rotation, reference_delta.linear(), dt);
      }
    }
  }

  stage_start = Clock::now();
  if (model_provisional_) backend_->resetModel();
  model_provisional_ = !started_ && times.source != TimeSource::none;
  if (model_provisional_) {  // kept until the next scan tells its motion
    provisional_cloud_ = cloud;
    provisional_motion_ = {times.source, Vector6d::Zero(), times.reference, gyro_.sweep};
    provisional_stamp_ = relative_stamp;
  } else {
    provisional_cloud_ = PointCloud();  // its memory back once the start is over
  }
  provisional_turned_by_gyro_ = model_provisional_ && gyro_.known;
  // The first scan of a start turned by the gyro: its stamp's turn in its reference frame is the gyro's.
  if (!started_ && gyro_.known) stamp_in_reference.linear() = gyro_.stamp_rotation;
  backend_->updateModel(reference_delta, relative_stamp);
  backend_->synchronize();
  result.times.model_update = millisecondsSince(stage_start);

  started_ = true;
  last_stamp_ = cloud.stamp;
  last_since_first_ = since_first;
  last_reference_ = times.reference;
  stamp_in_reference_ = stamp_in_reference;
  ++processed_;
  result.processed = true;
  result.pose = pose_;
  return result;
}

}  // namespace elo
