// elo_run --localize: the map loaded, each scan's localization said on stderr when its state changes, and
// a summary of the matches at the end. The localization itself is the drive session's.
#pragma once

#include <cstddef>
#include <memory>
#include <string>

#include "elo/config.hpp"
#include "elo/drive_session.hpp"

namespace elo::tools {

// Reads and prepares the map at `path` (readPreparedMap()), saying on stderr what that did.
std::shared_ptr<const MapCloud> loadLocalizationMap(const std::string& path, const Config& config);

// Says which poses the first accepted match placed after the fact, or which are not in the map frame at all.
void printPlacement(const DriveSession& session);

// Counts what the localizer did over the run.
class LocalizationReport {
 public:
  explicit LocalizationReport(LocalizationState initial) : last_state_(initial) {}
  // `result` of scan number `scan`, said on stderr when the state changed or a search found nothing;
  // `odometry_ms`: the odometry's time on the same scan (FrameResult::times.total).
  void add(size_t scan, const LocalizationResult& result, double odometry_ms);
  void print(const Localizer& localizer) const;

 private:
  size_t attempted_ = 0;
  size_t searches_ = 0;
  double milliseconds_ = 0.0;  // the localization's, over the tracked scans
  double odometry_milliseconds_ = 0.0;  // over the tracked scans
  double search_milliseconds_ = 0.0;
  size_t tracked_scans_ = 0;
  double inlier_share_ = 0.0;
  double rms_ = 0.0;
  LocalizationState last_state_;
};

}  // namespace elo::tools
