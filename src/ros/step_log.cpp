#include "step_log.hpp"

#include <ros/console.h>

namespace elo_ros {
namespace {

constexpr double kWarningPeriod = 5.0;  // s between repeats of one throttled warning

}  // namespace

void StepLog::log(const elo::DriveStep& step) {
  const elo::FrameResult& result = step.odometry;
  logRestart(step);
  if (!result.time_warning.empty()) {
    ROS_WARN_THROTTLE_NAMED(kWarningPeriod, name_, "per-point times: %s (deskew.time_source)", result.time_warning.c_str());
  }
  if (!result.sensor_warning.empty()) ROS_WARN_THROTTLE_NAMED(kWarningPeriod, name_, "%s", result.sensor_warning.c_str());
  logStartSearch(result);
  logTrackingHealth(result);
  if (result.processed) return;
  statistics_.scanSkipped(result.skip_reason);
  ROS_WARN_THROTTLE_NAMED(kWarningPeriod, name_, "scan skipped: %s", result.skip_reason.c_str());
}

void StepLog::logRestart(const elo::DriveStep& step) {
  if (step.odometry.reset) {
    ROS_WARN_NAMED(name_, "time went backwards (a bag replayed again?): the odometry restarted at the origin");
    statistics_.odometryRestarted("time went backwards");
  }
  if (step.odometry.gap_restart) {
    ROS_WARN_NAMED(name_,
                   "no scan for %.1f s, longer than model.time_window (%.1f s): the model restarted at the last pose, "
                   "and the odometry leaves out the motion during the gap",
                   step.since_last_processed, config_.model.time_window);
    statistics_.odometryRestarted("gap longer than model.time_window");
  }
}

void StepLog::logStartSearch(const elo::FrameResult& result) {
  const elo::StartSearchResult& search = result.start_search;
  if (!search.searched) return;
  const Eigen::Vector3d moved = search.motion.translation();
  if (result.gap > 0.0) {
    ROS_WARN_NAMED(name_,
                   "%.2f s since the last scan (dropped scans or a clock jump): the motion prior does not hold; "
                   "searched: %.2f m forward (%d candidates, %.0f ms)",
                   result.gap, moved.x(), search.candidates, search.milliseconds);
    return;
  }
  if (search.ambiguous) {
    ROS_WARN_NAMED(name_,
                   "start in motion: ambiguous, another motion fits the first two scans about as well (score %.3f "
                   "against %.3f); taken: %.2f m forward, which the scans do not confirm",
                   search.score, search.rival_score, moved.x());
  } else {
    ROS_INFO_NAMED(name_, "start in motion: %.2f m forward between the first two scans (%d candidates%s, %.0f ms)",
                   moved.x(), search.candidates,
                   search.rotation == elo::StartRotation::from_gyro ? " around the gyro's rotation" : "",
                   search.milliseconds);
  }
}

void StepLog::logTrackingHealth(const elo::FrameResult& result) {
  if (!result.sensor_height_warning.empty()) ROS_WARN_NAMED(name_, "%s", result.sensor_height_warning.c_str());
  if (result.tracking_restart) {
    ROS_ERROR_NAMED(name_, "lost: registrations refused %d times in a row (%s); the model restarts from this scan",
                    config_.motion.restart_after, result.refusal.c_str());
  } else if (!result.refusal.empty()) {
    ROS_WARN_THROTTLE_NAMED(kWarningPeriod, name_, "registration refused (%s): the pose is the motion prior's",
                            result.refusal.c_str());
  }
  if (result.recovered) ROS_INFO_NAMED(name_, "tracking recovered after refused registrations");
}

}  // namespace elo_ros
