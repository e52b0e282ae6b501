#include "run_report.hpp"

#include <sys/resource.h>

#include <algorithm>
#include <cstdio>
#include <numeric>
#include <utility>

namespace elo::tools {
namespace {

// Median and mean of one stage's times.
struct StageSummary {
  double mean = 0.0;
  double median = 0.0;
};

StageSummary summarise(std::vector<double> values) {
  StageSummary summary;
  if (values.empty()) return summary;
  summary.mean = std::accumulate(values.begin(), values.end(), 0.0) / values.size();
  std::nth_element(values.begin(), values.begin() + values.size() / 2, values.end());
  summary.median = values[values.size() / 2];
  return summary;
}

// Refused registrations by reason, recoveries, restarts, and whether the run ended lost.
void printTrackingHealth(const Odometry& odometry) {
  for (const auto& [reason, count] : odometry.refusalCounts()) {
    std::printf(", %zu registration%s refused (%s)", count, count > 1 ? "s" : "", reason.c_str());
  }
  if (odometry.recoveryCount() > 0) std::printf(", %zu recovered", odometry.recoveryCount());
  if (odometry.trackingRestartCount() > 0) {
    std::printf(", %zu model restart%s after refusals in a row", odometry.trackingRestartCount(),
                odometry.trackingRestartCount() > 1 ? "s" : "");
  }
  if (odometry.lost()) std::printf(", LOST at the end (the last registration was refused)");
}

// With imu.enabled: the scans the gyro could not turn and the samples dropped, by reason; the intervals
// whose specific force the accelerometers' gate left out.
void printImuHealth(const Odometry& odometry) {
  if (!odometry.config().imu.enabled) return;
  size_t fallbacks = 0;
  for (const auto& [reason, count] : odometry.imuFallbackCounts()) {
    std::printf(", %zu on the LiDAR-only prior (%s)", count, reason.c_str());
    fallbacks += count;
  }
  if (fallbacks == 0) std::printf(", every scan turned by the IMU");
  for (const auto& [reason, count] : odometry.imuDroppedCounts()) {
    std::printf(", %zu IMU sample%s dropped (%s)", count, count > 1 ? "s" : "", reason.c_str());
  }
  if (odometry.accelGatedCount() > 0) {
    std::printf(", %zu interval%s specific force gated (imu.accel_gate)", odometry.accelGatedCount(),
                odometry.accelGatedCount() > 1 ? "s'" : "'s");
  }
  const ImuStatus imu = odometry.imuStatus();
  if (imu.tilt_held > 0) {
    std::printf(", %zu scan%s turned back towards gravity (imu.tilt_hold_deg)", imu.tilt_held, imu.tilt_held > 1 ? "s" : "");
  }
}

// The scans counted: processed, skipped (unreadable, or unusable to the odometry), degenerate, started in
// motion, refused, misfitting the sensor.
void printCounts(const DriveSession& session, size_t scans) {
  const Odometry& odometry = session.odometry();
  std::printf("\nframes: %zu scans, %zu processed", scans, odometry.processedCount());
  size_t skipped = 0;
  for (const auto* counts : {&session.unreadableCounts(), &odometry.skippedCounts()}) {
    for (const auto& [reason, count] : *counts) {
      std::printf(", %zu skipped (%s)", count, reason.c_str());
      skipped += count;
    }
  }
  if (skipped > 0) std::printf("; a skipped scan's pose line repeats the last pose");
  if (odometry.degenerateCount() > 0) {
    std::printf(", %zu degenerate (the motion prior kept along what the scan did not constrain)",
                odometry.degenerateCount());
  }
  if (odometry.startSearchCount() > 0) {
    std::printf(", %zu start%s in motion searched", odometry.startSearchCount(), odometry.startSearchCount() > 1 ? "s" : "");
    if (odometry.ambiguousStartCount() > 0) {
      std::printf(" (%zu ambiguous: another motion fit about as well)", odometry.ambiguousStartCount());
    }
  }
  if (odometry.gapCount() > 0) {
    std::printf(", %zu gap%s between scans (the motion searched across)", odometry.gapCount(),
                odometry.gapCount() > 1 ? "s" : "");
  }
  printTrackingHealth(odometry);
  printImuHealth(odometry);
  if (odometry.sensorMisfitCount() > 0) {
    std::printf(", %zu not fitting the sensor model (the warning above)", odometry.sensorMisfitCount());
  }
}

}  // namespace

void RunReport::add(const DriveStep& step) {
  const FrameResult& result = step.odometry;
  if (!result.processed) return;
  projection_.push_back(result.times.projection);
  upload_.push_back(step.upload_milliseconds);
  features_.push_back(result.times.feature_extraction);
  registration_.push_back(result.times.registration);
  model_update_.push_back(result.times.model_update);
  total_.push_back(result.times.total);
}

double RunReport::meanTotalMilliseconds() const { return summarise(total_).mean; }

void RunReport::print(const DriveSession& session, size_t scans, size_t non_finite_points, double wall_seconds) const {
  if (non_finite_points > 0) std::printf("non-finite points skipped while reading: %zu\n", non_finite_points);
  printCounts(session, scans);
  std::printf("\n%-22s %10s %10s\n", "stage (ms)", "mean", "median");
  const std::pair<const char*, const std::vector<double>*> rows[] = {
      {"spherical projection", &projection_}, {"feature extraction", &features_},
      {"ICP optimization", &registration_},   {"model update", &model_update_},
      {"total", &total_}};
  for (const auto& [name, values] : rows) {
    const StageSummary s = summarise(*values);
    std::printf("%-22s %10.2f %10.2f\n", name, s.mean, s.median);
  }
  const double mean_total = summarise(total_).mean;
  const StageSummary reading = summarise(reading_);
  std::printf("%-22s %10.2f %10.2f   (not in the total: %.1f %% of it)\n", "reading scans", reading.mean, reading.median,
              mean_total > 0.0 ? 100.0 * reading.mean / mean_total : 0.0);
  const StageSummary upload = summarise(upload_);
  if (upload.mean > 0.0) {
    std::printf("%-22s %10.3f %10.3f   (%s)\n", "scan upload to GPU", upload.mean, upload.median,
                prefetching_ ? "what the frames still waited for; the rest ran beside the frame before"
                             : "part of the projection");
    std::printf("FPS without the upload: %.1f\n", 1000.0 / (mean_total - upload.mean));
  }
  rusage usage{};
  getrusage(RUSAGE_SELF, &usage);
  const int threads = session.config().runtime.threads;
  std::printf("FPS: %.1f (pipeline), %.1f (wall, with reading scans); backend: %s; threads: %s; peak memory: %.0f MiB\n",
              mean_total > 0.0 ? 1000.0 / mean_total : 0.0, wall_seconds > 0.0 ? total_.size() / wall_seconds : 0.0,
              session.odometry().backend().name(), threads > 0 ? std::to_string(threads).c_str() : "all",
              usage.ru_maxrss / 1024.0);
}

}  // namespace elo::tools
