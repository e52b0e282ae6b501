// elo_run's loop over the played scans: each is read (one ahead, prefetched), given to the drive session
// or, unreadable, skipped; what the session made of it is said on stderr, timed and, with --timing, written.
#pragma once

#include <fstream>
#include <optional>
#include <set>
#include <string>
#include <vector>

#include "elo/drive_session.hpp"
#include "elo/io/scan_source.hpp"
#include "imu_feed.hpp"
#include "localization_output.hpp"
#include "options.hpp"
#include "run_report.hpp"

namespace elo::tools {

// A scan that was read, or why it could not be read or used: the counted reason and the reader's
// message (a missing, truncated or malformed file or message).
struct ScanRead {
  std::optional<LoadedScan> scan;
  std::string reason;
  std::string detail;
};

class ScanLoop {
 public:
  // Throws IoError when --timing's file cannot be written, or the IMU cannot be read (ImuFeed).
  ScanLoop(const Options& options, const ScanSource& source, DriveSession& session);

  // Reads and processes every played scan. A scan that cannot be read is skipped (its line repeats the
  // last pose) or, with --strict, ends the run with an IoError; a localization that fails ends it too.
  // Reads each scan one ahead and prefetches it before processing the one before it, so that a device
  // backend uploads it meanwhile (elo::Odometry::prefetch()).
  void run(const std::vector<PlayedScan>& played);

  // The scans done, whose lines the trajectory holds: all of them, or those before a failure.
  size_t completed() const { return completed_; }
  const RunReport& report() const { return report_; }
  const std::optional<LocalizationReport>& localizationReport() const { return localization_report_; }
  size_t nonFinitePoints() const { return non_finite_points_; }
  const ImuFeed& imu() const { return imu_; }

 private:
  // Reads the scan, stamped as played, and prefetches it unless --no-prefetch.
  ScanRead readPlayed(const PlayedScan& played);
  DriveStep step(const PlayedScan& played, const ScanRead& read);
  DriveStep skipUnreadable(size_t scan, double stamp, const ScanRead& read);
  // The odometry's warnings, refusals, skips and restarts on this scan.
  void tellOdometry(size_t scan, const FrameResult& result);
  // Each warning a reader gave, said once: a driver's fields are the same in every cloud.
  void warnOnce(size_t scan, const std::string& warning);

  const Options& options_;
  const ScanSource& source_;
  DriveSession& session_;
  ImuFeed imu_;
  std::ofstream timing_;
  RunReport report_;
  std::optional<LocalizationReport> localization_report_;
  size_t completed_ = 0;
  size_t non_finite_points_ = 0;
  std::set<std::string> warned_;
};

}  // namespace elo::tools
