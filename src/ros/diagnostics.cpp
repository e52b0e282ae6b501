#include "diagnostics.hpp"

#include <diagnostic_msgs/DiagnosticStatus.h>

#include <algorithm>
#include <cmath>
#include <sstream>

namespace elo_ros {
namespace {

double mean(double sum, size_t count) { return count > 0 ? sum / count : 0.0; }

size_t total(const std::map<std::string, size_t>& counts) {
  size_t sum = 0;
  for (const auto& [reason, count] : counts) sum += count;
  return sum;
}

std::string vectorText(const Eigen::Vector3d& vector) {
  std::ostringstream text;
  text.precision(4);
  text << vector.x() << ", " << vector.y() << ", " << vector.z();
  return text.str();
}

std::string degreesPerSecond(const Eigen::Vector3d& rate) { return vectorText(rate * 180.0 / M_PI); }

}  // namespace

std::string PipelineStatistics::Window::problems() const {
  if (received == 0 && processed == 0) return "no clouds received";
  std::ostringstream text;
  const auto add = [&](size_t count, const char* what) {
    if (count > 0) text << (text.tellp() > 0 ? ", " : "") << count << ' ' << what;
  };
  add(dropped, "dropped (processing slower than input)");
  add(rejected, "rejected");
  add(skipped, "skipped");
  add(failed_registrations, "registrations failed");
  add(restarts, "odometry restarts");
  add(time_warnings, "scans with unusable per-point times");
  add(sensor_misfits, "scans not fitting the sensor model");
  add(ambiguous_starts, "ambiguous starts (the motion at a start not told apart)");
  add(refused, "registrations refused (beyond the motion bounds or collapsed)");
  return text.str();
}

PipelineStatistics::PipelineStatistics() : window_start_(Clock::now()) {}

void PipelineStatistics::cloudReceived() {
  std::lock_guard<std::mutex> lock(mutex_);
  ++received_;
  ++window_.received;
}

void PipelineStatistics::cloudsDropped(size_t count) {
  std::lock_guard<std::mutex> lock(mutex_);
  dropped_ += count;
  window_.dropped += count;
}

void PipelineStatistics::cloudRejected(const std::string& reason) {
  std::lock_guard<std::mutex> lock(mutex_);
  ++rejected_[reason];
  ++window_.rejected;
}

void PipelineStatistics::scanSkipped(const std::string& reason) {
  std::lock_guard<std::mutex> lock(mutex_);
  ++skipped_[reason];
  ++window_.skipped;
}

void PipelineStatistics::odometryRestarted(const std::string& reason) {
  std::lock_guard<std::mutex> lock(mutex_);
  ++restarts_[reason];
  ++window_.restarts;
}

void PipelineStatistics::scanProcessed(const elo::FrameResult& result, double latency_ms) {
  std::lock_guard<std::mutex> lock(mutex_);
  ++processed_;
  ++window_.processed;
  window_.processing_ms_sum += result.times.total;
  window_.processing_ms_max = std::max(window_.processing_ms_max, result.times.total);
  window_.latency_ms_sum += latency_ms;
  window_.latency_ms_max = std::max(window_.latency_ms_max, latency_ms);
  if (result.registration.failed) {
    ++failed_registrations_;
    ++window_.failed_registrations;
  }
  if (result.registration.degeneracy.any()) {
    ++degenerate_scans_;
  }
  if (!result.time_warning.empty()) {
    ++time_warnings_[result.time_warning];
    ++window_.time_warnings;
  }
  if (!result.sensor_warning.empty()) {
    ++sensor_misfits_;
    ++window_.sensor_misfits;
    last_sensor_warning_ = result.sensor_warning;
  }
  if (!result.refusal.empty()) {
    ++refusals_[result.refusal];
    ++window_.refused;
  }
  lost_ = !result.refusal.empty();
  if (result.recovered) ++recoveries_;
  if (result.tracking_restart) {
    ++tracking_restarts_;
    ++window_.tracking_restarts;
  }
  if (!result.sensor_height_warning.empty()) last_sensor_height_warning_ = result.sensor_height_warning;
  if (result.start_search.searched) ++start_searches_;
  if (result.gap > 0.0) ++gaps_;
  if (result.start_search.ambiguous) {
    ++ambiguous_starts_;
    ++window_.ambiguous_starts;
  }
  if (result.registration.iterations > 0) last_registration_ = result.registration;
}

void PipelineStatistics::report(diagnostic_updater::DiagnosticStatusWrapper& status) {
  std::lock_guard<std::mutex> lock(mutex_);
  const Clock::time_point now = Clock::now();
  const double seconds = std::chrono::duration<double>(now - window_start_).count();
  const Window& w = window_;

  std::string problems = w.problems();
  // Only the latest scan: a degenerate scan now and then on an open road needs no alarm, a run of them
  // (a tunnel) warns for as long as it lasts.
  const elo::Degeneracy& degeneracy = last_registration_.degeneracy;
  if (degeneracy.any()) {
    problems += (problems.empty() ? "" : ", ") + std::string("latest scan degenerate along ") + degeneracy.describe();
  }
  if (lost_ || w.tracking_restarts > 0) {
    // Lost: the latest scans' registrations were refused; their poses are the motion prior's.
    status.summary(diagnostic_msgs::DiagnosticStatus::ERROR,
                   std::string(lost_ ? "lost: the latest registration was refused" : "tracking again") +
                       (w.tracking_restarts > 0 ? ", model restarted after refusals in a row" : "") +
                       (problems.empty() ? "" : ", " + problems));
  } else if (problems.empty()) {
    status.summary(diagnostic_msgs::DiagnosticStatus::OK, "tracking");
  } else {
    status.summary(diagnostic_msgs::DiagnosticStatus::WARN, problems);
  }
  status.add("input rate (Hz)", seconds > 0.0 ? w.received / seconds : 0.0);
  status.add("processing rate (Hz)", seconds > 0.0 ? w.processed / seconds : 0.0);
  status.add("processing time mean (ms)", mean(w.processing_ms_sum, w.processed));
  status.add("processing time max (ms)", w.processing_ms_max);
  status.add("latency mean (ms)", mean(w.latency_ms_sum, w.processed));
  status.add("latency max (ms)", w.latency_ms_max);
  const elo::NormalEquations& last = last_registration_.last;
  status.add("non-ground inlier ratio", last.nonground.inlierRatio());
  status.add("ground inlier ratio", last.ground.inlierRatio());
  status.add("fusion weight", last_registration_.weight);
  status.add("registration iterations", last_registration_.iterations);
  // Share of the constraint along the least constrained direction (see elo/pipeline/degeneracy.hpp).
  status.add("smallest constraint eigenvalue", degeneracy.eigenvalues[0]);
  status.add("degenerate directions", degeneracy.any() ? degeneracy.describe() : "none");
  status.add("clouds received", received_);
  status.add("scans processed", processed_);
  status.add("scans dropped", dropped_);
  status.add("registrations failed", failed_registrations_);
  status.add("scans degenerate", degenerate_scans_);
  status.add("start searches", start_searches_);
  status.add("ambiguous starts", ambiguous_starts_);
  status.add("gaps searched", gaps_);
  for (const auto& [reason, count] : refusals_) status.add("registrations refused: " + reason, count);
  status.add("recoveries", recoveries_);
  status.add("model restarts after refusals", tracking_restarts_);
  if (!last_sensor_height_warning_.empty()) status.add("sensor height", last_sensor_height_warning_);
  for (const auto& [reason, count] : rejected_) status.add("clouds rejected: " + reason, count);
  for (const auto& [reason, count] : skipped_) status.add("scans skipped: " + reason, count);
  for (const auto& [reason, count] : restarts_) status.add("odometry restarts: " + reason, count);
  for (const auto& [reason, count] : time_warnings_) status.add("per-point times: " + reason, count);
  status.add("scans not fitting the sensor model", sensor_misfits_);
  if (sensor_misfits_ > 0) status.add("sensor model: latest misfit", last_sensor_warning_);

  window_start_ = now;
  window_ = Window();
}

void ImuStatistics::messageReceived(double stamp) {
  std::lock_guard<std::mutex> lock(mutex_);
  ++received_;
  if (window_.received++ == 0) window_.first_stamp = stamp;
  window_.last_stamp = stamp;
}

void ImuStatistics::messageUnused(const std::string& reason) {
  std::lock_guard<std::mutex> lock(mutex_);
  ++unused_[reason];
  ++window_.unused;
}

void ImuStatistics::update(const elo::ImuStatus& status) {
  std::lock_guard<std::mutex> lock(mutex_);
  core_ = status;
}

void ImuStatistics::report(diagnostic_updater::DiagnosticStatusWrapper& status) {
  std::lock_guard<std::mutex> lock(mutex_);
  const Window& w = window_;
  const double span = w.last_stamp - w.first_stamp;
  const double rate = w.received > 1 && span > 0.0 ? (w.received - 1) / span : 0.0;
  const size_t fallbacks = total(core_.fallbacks);
  const size_t dropped = total(core_.dropped);

  std::ostringstream problems;
  const auto add = [&](const std::string& problem) { problems << (problems.tellp() > 0 ? ", " : "") << problem; };
  if (w.received == 0) {
    add("IMU silent: no Imu message");
  } else if (rate < min_rate_hz_) {
    std::ostringstream text;
    text << "IMU rate " << rate << " Hz under imu.min_rate_hz (" << min_rate_hz_ << ")";
    add(text.str());
  }
  if (w.unused > 0) add(std::to_string(w.unused) + " Imu messages unused");
  if (dropped > reported_dropped_) add(std::to_string(dropped - reported_dropped_) + " IMU samples dropped");
  if (fallbacks > reported_fallbacks_) {
    add(std::to_string(fallbacks - reported_fallbacks_) + " scans on the LiDAR-only prior");
  }
  if (problems.tellp() > 0) {
    status.summary(diagnostic_msgs::DiagnosticStatus::WARN, problems.str());
  } else {
    status.summary(diagnostic_msgs::DiagnosticStatus::OK, "every scan turned by the gyro");
  }
  status.add("IMU rate (Hz)", rate);
  status.add("Imu messages received", received_);
  for (const auto& [reason, count] : unused_) status.add("Imu messages unused: " + reason, count);
  status.add("IMU samples taken", core_.samples_taken);
  for (const auto& [reason, count] : core_.dropped) status.add("IMU samples dropped: " + reason, count);
  status.add("scans on the LiDAR-only prior", fallbacks);
  for (const auto& [reason, count] : core_.fallbacks) status.add("scans on the LiDAR-only prior: " + reason, count);
  status.add("gyro bias (deg/s)", degreesPerSecond(core_.gyro_bias));
  status.add("gravity in the odometry frame (m/s^2)", core_.gravity_known ? vectorText(core_.gravity) : "not estimated yet");
  status.add("accelerometer bias (m/s^2)", vectorText(core_.accel_bias));
  status.add("accelerometer intervals gated", core_.accel_gated);
  std::ostringstream tilt;
  if (core_.tilt_deg) tilt << *core_.tilt_deg; else tilt << "not measured yet";
  status.add("tilt against gravity (deg)", tilt.str());
  status.add("scans held to gravity", core_.tilt_held);

  reported_fallbacks_ = fallbacks;
  reported_dropped_ = dropped;
  window_ = Window();
}

}  // namespace elo_ros
