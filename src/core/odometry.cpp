#include "elo/odometry.hpp"

#include <chrono>
#include <cmath>

namespace elo {

namespace {

using Clock = std::chrono::steady_clock;

double millisecondsSince(Clock::time_point start) {
  return std::chrono::duration<double, std::milli>(Clock::now() - start).count();
}

}  // namespace

Odometry::Odometry(const Config& config) : config_(config), motion_(config.model.motion_prior) {
  validate(config_);
  backend_ = makeBackend(config_);
}

void Odometry::reset() {
  backend_->resetModel();
  motion_.reset();
  pose_ = Eigen::Isometry3d::Identity();
  started_ = false;
}

FrameResult Odometry::skip(const std::string& reason) {
  ++skipped_[reason];
  FrameResult result;
  result.skip_reason = reason;
  result.pose = pose_;
  return result;
}

FrameResult Odometry::process(const PointCloud& cloud) {
  if (cloud.points.empty()) return skip("empty cloud");
  if (!std::isfinite(cloud.stamp)) return skip("stamp not finite");
  bool restarted = false;
  if (started_ && cloud.stamp == last_stamp_) return skip("duplicate stamp");
  if (started_ && cloud.stamp < last_stamp_) {
    // A bag played in a loop, or a clock jump: the old model and motion describe another time.
    reset();
    restarted = true;
  }
  if (!started_) first_stamp_ = cloud.stamp;

  const auto frame_start = Clock::now();
  FrameResult result;
  result.reset = restarted;
  // Observation times are kept relative to the first scan: a float holds them to a millisecond for hours.
  const float relative_stamp = static_cast<float>(cloud.stamp - first_stamp_);

  auto stage_start = Clock::now();
  const size_t occupied = backend_->projectScan(cloud, relative_stamp);
  result.times.projection = millisecondsSince(stage_start);
  if (occupied < kMinOccupiedPixels) {
    FrameResult skipped = skip("too few valid points");
    skipped.reset = restarted;
    return skipped;
  }

  stage_start = Clock::now();
  backend_->segmentGround();
  backend_->estimateNormals();
  backend_->buildGroundMap();
  result.times.feature_extraction = millisecondsSince(stage_start);

  if (started_) {
    const double dt = cloud.stamp - last_stamp_;
    stage_start = Clock::now();
    result.registration = registerScan(*backend_, motion_.predict(dt), motion_.informed(), config_.registration);
    result.times.registration = millisecondsSince(stage_start);
    result.delta = result.registration.model_from_scan;
    pose_ = pose_ * result.delta;
    motion_.record(result.delta, dt);
  }

  stage_start = Clock::now();
  backend_->updateModel(result.delta, relative_stamp);
  result.times.model_update = millisecondsSince(stage_start);

  started_ = true;
  last_stamp_ = cloud.stamp;
  ++processed_;
  result.processed = true;
  result.pose = pose_;
  result.times.total = millisecondsSince(frame_start);
  return result;
}

}  // namespace elo
