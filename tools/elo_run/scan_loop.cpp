#include "scan_loop.hpp"

#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <stdexcept>

#include "elo/io/io_error.hpp"

namespace elo::tools {
namespace {

ScanRead readScan(const ScanSource& source, size_t index) {
  try {
    return {source.read(index), "", ""};
  } catch (const UnusableScan& error) {
    return {std::nullopt, error.reason(), error.what()};
  }
}

void writeTimingRow(std::ofstream& csv, size_t index, double stamp, const FrameResult& r) {
  csv << index << ',' << stamp << ',' << (r.processed ? 1 : 0) << ',' << r.times.projection << ','
      << r.times.feature_extraction << ',' << r.times.registration << ',' << r.times.model_update << ','
      << r.times.total << ',' << r.registration.iterations << ',' << r.deskew_rounds << ','
      << r.registration.last.nonground.inliers << ',' << r.registration.last.ground.inliers << ','
      << r.registration.weight << ',' << r.registration.degeneracy.eigenvalues[0] << ','
      << r.registration.degeneracy.describe() << ',' << r.start_search.candidates << ','
      << r.start_search.milliseconds << '\n';
}

void showProgress(size_t done, size_t total) {
  constexpr int kWidth = 40;
  const int filled = static_cast<int>(kWidth * done / std::max<size_t>(total, 1));
  std::fprintf(stderr, "\r[%s%s] %zu/%zu", std::string(filled, '#').c_str(), std::string(kWidth - filled, ' ').c_str(),
               done, total);
  if (done == total) std::fprintf(stderr, "\n");
}

}  // namespace

ScanLoop::ScanLoop(const Options& options, const ScanSource& source, DriveSession& session)
    : options_(options),
      source_(source),
      session_(session),
      imu_(options, session.config()),
      report_(options.prefetch) {
  if (session.localizer() != nullptr) localization_report_.emplace(session.localizer()->state());
  if (options.timing_csv.empty()) return;
  timing_.open(options.timing_csv);
  if (!timing_) throw IoError("cannot write " + options.timing_csv);
  timing_ << "frame,stamp,processed,projection_ms,features_ms,registration_ms,model_update_ms,total_ms,"
             "iterations,deskew_rounds,nonground_inliers,ground_inliers,weight,smallest_eigenvalue,degenerate,"
             "start_search_candidates,start_search_ms\n";
}

void ScanLoop::run(const std::vector<PlayedScan>& played) {
  const bool progress = !options_.quiet && isatty(STDERR_FILENO);
  ScanRead next = played.empty() ? ScanRead{} : readPlayed(played[0]);
  for (size_t i = 0; i < played.size(); ++i) {
    const ScanRead current = std::move(next);
    if (i + 1 < played.size()) next = readPlayed(played[i + 1]);
    const DriveStep done = step(played[i], current);
    if (localization_report_) {
      if (!done.localization) throw std::runtime_error(done.localization_failure);
      localization_report_->add(played[i].index, *done.localization, done.odometry.times.total);
    }
    ++completed_;
    if (timing_.is_open()) writeTimingRow(timing_, i, played[i].stamp, done.odometry);
    if (progress) showProgress(i + 1, played.size());
  }
}

ScanRead ScanLoop::readPlayed(const PlayedScan& played) {
  const auto start = std::chrono::steady_clock::now();
  ScanRead read = readScan(source_, played.index);
  report_.addReading(std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count());
  if (read.scan) {
    non_finite_points_ += read.scan->non_finite_points;
    elo::asPlayed(played, read.scan->cloud);
    if (options_.prefetch) session_.prefetch(read.scan->cloud);
  }
  return read;
}

DriveStep ScanLoop::step(const PlayedScan& played, const ScanRead& read) {
  const size_t scan = played.index;
  if (!read.scan) return skipUnreadable(scan, played.stamp, read);
  warnOnce(scan, read.scan->warning);
  imu_.feedUpTo(played.stamp, session_);
  const DriveStep step = session_.process(read.scan->cloud);
  tellOdometry(scan, step.odometry);
  report_.add(step);
  if (session_.feedMap(step, read.scan->cloud) == DriveSession::MapFeed::dropped) {
    std::fprintf(stderr, "\nwarning: the map's thread fell behind: a scan left out of the map\n");
  }
  return step;
}

DriveStep ScanLoop::skipUnreadable(size_t scan, double stamp, const ScanRead& read) {
  if (options_.strict) {
    throw IoError("scan " + std::to_string(scan) + ": " + read.detail + " (--strict stops at a scan that cannot be read)");
  }
  std::fprintf(stderr, "\nscan %zu skipped: %s: %s\n", scan, read.reason.c_str(), read.detail.c_str());
  return session_.skipUnreadable(stamp, read.reason);
}

void ScanLoop::tellOdometry(size_t scan, const FrameResult& result) {
  // The first misfit only; the summary counts them.
  if (!result.sensor_warning.empty() && session_.odometry().sensorMisfitCount() == 1) {
    std::fprintf(stderr, "\nscan %zu: warning: %s\n", scan, result.sensor_warning.c_str());
  }
  if (!result.sensor_height_warning.empty()) {
    std::fprintf(stderr, "\nscan %zu: warning: %s\n", scan, result.sensor_height_warning.c_str());
  }
  if (!result.refusal.empty()) {
    std::fprintf(stderr, "\nscan %zu: registration refused (%s)%s\n", scan, result.refusal.c_str(),
                 result.tracking_restart ? "; model restarted from this scan" : "");
  }
  if (result.recovered) std::fprintf(stderr, "\nscan %zu: tracking recovered\n", scan);
  if (result.gap > 0.0) {
    std::fprintf(stderr, "\nscan %zu: %.2f s after the last scan (dropped scans or a clock jump): motion searched, %.2f m\n",
                 scan, result.gap, result.delta.translation().norm());
  }
  if (!result.imu_fallback.empty()) std::fprintf(stderr, "\nscan %zu: LiDAR-only prior: %s\n", scan, result.imu_fallback.c_str());
  if (!result.processed) std::fprintf(stderr, "\nscan %zu skipped: %s\n", scan, result.skip_reason.c_str());
  if (result.reset) std::fprintf(stderr, "\nscan %zu: time went backwards, odometry restarted\n", scan);
  if (result.gap_restart) {
    std::fprintf(stderr, "\nscan %zu: gap longer than model.time_window, model restarted at the last pose\n", scan);
  }
}

void ScanLoop::warnOnce(size_t scan, const std::string& warning) {
  if (!warning.empty() && warned_.insert(warning).second) std::fprintf(stderr, "\nscan %zu: warning: %s\n", scan, warning.c_str());
}

}  // namespace elo::tools
