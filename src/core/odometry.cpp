#include "elo/odometry.hpp"

#include <cmath>

#include "core/elapsed_time.hpp"
#include "elo/deskew.hpp"
#include "elo/se3.hpp"
#include "elo/sensor_fit.hpp"

namespace elo {

Odometry::Odometry(const Config& config) : config_(config), motion_(config.model.motion_prior) {
  validate(config_);
  backend_ = makeBackend(config_, &backend_warning_);
}

void Odometry::restartModel() {
  backend_->resetModel();
  motion_.reset();
  started_ = false;
}

void Odometry::reset() {
  restartModel();
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

Vector6d Odometry::registerAndDeskew(const Eigen::Isometry3d& guess, double dt, const Vector6d& deskewed,
                                     double farthest, FrameResult& result) {
  Vector6d deskewed_under = deskewed;
  const ScanRefresh deskew_again = [&](const Eigen::Isometry3d& estimate, bool converged) {
    if (result.time_source == TimeSource::none) return false;
    // Against a model of the first scan as measured, the scan as measured registers best (the two are
    // bent alike): it is deskewed once, whatever deskew.rounds says, when the registration has converged,
    // only to replace that model.
    if (model_provisional_ && !converged) return false;
    const int rounds = model_provisional_ ? 1 : config_.deskew.rounds;
    const Vector6d velocity = sweepVelocity(estimate, dt);
    if (result.deskew_rounds >= rounds || !changesRegistration(deskewed_under, velocity, farthest, config_.registration)) {
      return false;
    }
    deskewScanAgain(velocity, result);
    deskewed_under = velocity;
    return !model_provisional_;
  };
  const auto stage_start = Clock::now();
  result.registration = registerScan(*backend_, guess, motion_.informed(), config_.registration, deskew_again);
  result.times.registration = millisecondsSince(stage_start) - result.times.deskew;
  return deskewed_under;
}

Eigen::Isometry3d Odometry::initialGuess(double dt, FrameResult& result) {
  if (motion_.known() || !config_.start_search.enabled) return motion_.predict(dt);
  result.start_search = searchStartMotion(*backend_, dt, config_);
  ++start_searches_;
  if (result.start_search.ambiguous) ++ambiguous_starts_;
  return result.start_search.motion;
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
  const double since_first = secondsSinceFirst(cloud.stamp);

  // Observation times are kept relative to the first scan: a float holds them to a millisecond for hours.
  const float relative_stamp = static_cast<float>(since_first);
  const CloudTimes times = inspectTimes(cloud, config_);
  result.time_source = times.source;
  result.time_warning = times.warning;
  result.points_without_time = times.outside_sweep;
  if (!times.warning.empty()) ++time_warnings_[times.warning];
  result.sensor_warning = sensorWarning(cloud);
  // The motion is estimated between the scans' reference instants: the stamps' interval, moved by how the
  // references lie within their sweeps (0 but for `field` times).
  const double dt = started_ ? since_first - last_since_first_ + (times.reference - last_reference_) : 0.0;

  auto stage_start = Clock::now();
  // Deskewed under the velocity last registered: the first scans (none yet) as they were measured.
  const Vector6d sweep_velocity = started_ ? motion_.velocity() : Vector6d::Zero();
  const size_t occupied = backend_->projectScan(cloud, relative_stamp, {times.source, sweep_velocity, times.reference});
  result.times.projection = millisecondsSince(stage_start);
  if (occupied < minOccupiedPixels()) {
    FrameResult skipped = skip("too few valid points");
    skipped.reset = result.reset;
    skipped.gap_restart = result.gap_restart;
    skipped.time_warning = result.time_warning;
    skipped.sensor_warning = result.sensor_warning;
    return skipped;
  }

  stage_start = Clock::now();
  backend_->segmentGround();
  backend_->estimateNormals();
  backend_->buildGroundMap();
  backend_->synchronize();  // a device backend's stages run on after the calls return
  result.times.feature_extraction = millisecondsSince(stage_start);

  // The scan's frame at its reference instant, relative to the last scan's; and its stamp's frame in it.
  Eigen::Isometry3d reference_delta = Eigen::Isometry3d::Identity();
  Eigen::Isometry3d stamp_in_reference = Eigen::Isometry3d::Identity();
  if (started_) {
    const Eigen::Isometry3d guess = initialGuess(dt, result);
    const Vector6d deskewed_under = registerAndDeskew(guess, dt, sweep_velocity, times.farthest, result);
    result.times.registration += result.start_search.milliseconds;
    reference_delta = result.registration.model_from_scan;
    // Under the velocity the points were moved with, the sensor at the stamp (time 0, `reference`
    // seconds before the reference instant) is exp(-reference * velocity) in the reference frame.
    stamp_in_reference = expSE3(-times.reference * deskewed_under);
    // The first scan of a start had no velocity to place its stamp in its sweep; registered against it
    // as measured (bent alike), this scan measured the motion between like instants of the two sweeps.
    if (model_provisional_) stamp_in_reference_ = expSE3(-last_reference_ * deskewed_under);
    // T^{t-1}_t between the stamps; exactly the reference delta when both references are the stamps.
    result.delta = stamp_in_reference_.inverse() * reference_delta * stamp_in_reference;
    pose_ = pose_ * result.delta;
    motion_.record(reference_delta, dt);
    const Degeneracy& degeneracy = result.registration.degeneracy;
    if (degeneracy.any()) ++degenerate_;
    motion_.holdVelocityAlong(degeneracy.priorShare());
  }

  stage_start = Clock::now();
  if (model_provisional_) backend_->resetModel();
  model_provisional_ = !started_ && times.source != TimeSource::none;
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
