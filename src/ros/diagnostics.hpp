// What the node has done with the clouds it received and, with an IMU, with its messages, for
// diagnostic_updater: totals since the start, and rates and timings over the window since the previous report.
#pragma once

#include <diagnostic_updater/DiagnosticStatusWrapper.h>

#include <chrono>
#include <map>
#include <mutex>
#include <string>

#include "elo/imu/imu_track.hpp"
#include "elo/pipeline/odometry.hpp"

namespace elo_ros {

class PipelineStatistics {
 public:
  PipelineStatistics();

  void cloudReceived();
  // Clouds that waited for the worker and a newer one replaced (latest-scan mode).
  void cloudsDropped(size_t count);
  // The cloud could not be converted or placed (see cloud_conversion.hpp); `reason` groups the counts.
  void cloudRejected(const std::string& reason);
  // The core skipped the scan (elo::FrameResult::skip_reason).
  void scanSkipped(const std::string& reason);
  // `latency_ms`: from the cloud's arrival to its odometry being published, queueing included.
  void scanProcessed(const elo::FrameResult& result, double latency_ms);
  // The odometry restarted at a scan (processed or skipped); `reason` groups the counts.
  void odometryRestarted(const std::string& reason);

  // Fills `status` and starts a new window. WARN when the window saw no cloud at all, or a drop,
  // rejection, skip, restart, failed registration, scan whose per-point times were not (all) usable
  // (elo::FrameResult::time_warning) or scan that does not fit the sensor model
  // (elo::FrameResult::sensor_warning), and while the latest scan is degenerate.
  void report(diagnostic_updater::DiagnosticStatusWrapper& status);

 private:
  using Clock = std::chrono::steady_clock;

  struct Window {
    size_t received = 0;
    size_t processed = 0;
    size_t dropped = 0;
    size_t rejected = 0;
    size_t skipped = 0;
    size_t failed_registrations = 0;
    size_t restarts = 0;
    size_t time_warnings = 0;
    size_t sensor_misfits = 0;
    size_t ambiguous_starts = 0;
    size_t refused = 0;            // registrations refused (elo::FrameResult::refusal)
    size_t tracking_restarts = 0;  // model restarts after refusals in a row
    double processing_ms_sum = 0.0;
    double processing_ms_max = 0.0;
    double latency_ms_sum = 0.0;
    double latency_ms_max = 0.0;

    // Why the window deserves a warning; empty when it does not.
    std::string problems() const;
  };

  std::mutex mutex_;
  Clock::time_point window_start_;
  Window window_;
  size_t received_ = 0;
  size_t processed_ = 0;
  size_t dropped_ = 0;
  size_t failed_registrations_ = 0;
  size_t degenerate_scans_ = 0;
  size_t start_searches_ = 0;    // elo::FrameResult::start_search
  size_t gaps_ = 0;              // elo::FrameResult::gap
  size_t ambiguous_starts_ = 0;  // ... whose winner did not stand out
  std::map<std::string, size_t> refusals_;  // refused registrations by reason
  size_t recoveries_ = 0;
  size_t tracking_restarts_ = 0;
  bool lost_ = false;  // the latest registration was refused
  std::string last_sensor_height_warning_;
  std::map<std::string, size_t> rejected_;
  std::map<std::string, size_t> skipped_;
  std::map<std::string, size_t> restarts_;
  std::map<std::string, size_t> time_warnings_;  // elo::FrameResult::time_warning
  size_t sensor_misfits_ = 0;                     // scans with an elo::FrameResult::sensor_warning
  std::string last_sensor_warning_;
  elo::RegistrationResult last_registration_;
};

// The IMU's state (imu.enabled, docs/imu.md), a status of its own: the Imu messages received and their
// rate, those the node could not hand to the odometry, and the core's elo::ImuStatus (samples dropped,
// scans fallen back to the LiDAR-only prior, the gyro's bias).
class ImuStatistics {
 public:
  explicit ImuStatistics(double min_rate_hz) : min_rate_hz_(min_rate_hz) {}

  // `stamp`: the message's header stamp (s).
  void messageReceived(double stamp);
  // A message the node did not hand to the odometry, by reason.
  void messageUnused(const std::string& reason);
  // After each scan: the core's state (elo::DriveSession::imuStatus()).
  void update(const elo::ImuStatus& status);

  // Fills `status` and starts a new window. WARN when the window saw no message (the IMU silent), a rate
  // under imu.min_rate_hz (by the messages' stamps, so that a bag played slower does not warn), a message
  // unused, a sample dropped or a scan on the LiDAR-only prior.
  void report(diagnostic_updater::DiagnosticStatusWrapper& status);

 private:
  struct Window {
    size_t received = 0;
    size_t unused = 0;
    double first_stamp = 0.0;
    double last_stamp = 0.0;
  };

  double min_rate_hz_;
  std::mutex mutex_;
  Window window_;
  size_t received_ = 0;
  std::map<std::string, size_t> unused_;
  elo::ImuStatus core_;
  size_t reported_fallbacks_ = 0;  // the core's scans fallen back and samples dropped at the last report
  size_t reported_dropped_ = 0;
};

}  // namespace elo_ros
