#include "localization_output.hpp"

#include <cstdio>

#include "elo/io/map_pcd.hpp"

namespace elo::tools {

std::shared_ptr<const MapCloud> loadLocalizationMap(const std::string& path, const Config& config) {
  PreparedMap map = readPreparedMap(path, config.localization.normal_radius);
  const MapPreparation& preparation = map.preparation;
  std::fprintf(stderr, "map %s: %zu points", path.c_str(), map.cloud->size());
  if (preparation.non_finite_dropped > 0) std::fprintf(stderr, ", %zu non-finite dropped", preparation.non_finite_dropped);
  if (preparation.bad_normals > 0) std::fprintf(stderr, ", %zu normals not unit vectors (dropped)", preparation.bad_normals);
  if (preparation.estimated) std::fprintf(stderr, ", normals estimated (%zu fitted)", preparation.normals_estimated);
  std::fprintf(stderr, "\n");
  return map.cloud;
}

void printPlacement(const DriveSession& session) {
  if (session.linesPlacedByFirstMatch() > 0) {
    std::printf("localization: the %zu scans before the first accepted match were placed in the map by it\n",
                session.linesPlacedByFirstMatch());
  }
  if (session.linesWaitingForMatch() > 0) {
    std::fprintf(stderr, "warning: no pose in the map was found: the %zu poses written while waiting for one are "
                 "the odometry's, in the frame of its first scan\n", session.linesWaitingForMatch());
  }
}

void LocalizationReport::add(size_t scan, const LocalizationResult& result, double odometry_ms) {
  if (result.state != last_state_ || (result.searched && !result.matched)) {
    std::fprintf(stderr, "\nscan %zu: localization %s%s%s\n", scan, stateName(result.state),
                 result.refusal.empty() ? "" : ": ", result.refusal.c_str());
  }
  if (result.attempted) ++attempted_;
  if (result.searched) {
    ++searches_;
    search_milliseconds_ += result.milliseconds;
  } else if (result.attempted || result.state == LocalizationState::tracking) {
    // A tracked scan (one waiting for a pose, or lost between searches, does no map match).
    milliseconds_ += result.milliseconds;
    odometry_milliseconds_ += odometry_ms;
    ++tracked_scans_;
  }
  if (result.matched) {
    inlier_share_ += result.health.inlier_share;
    rms_ += result.health.rms;
  }
  last_state_ = result.state;
}

void LocalizationReport::print(const Localizer& localizer) const {
  const size_t accepted = localizer.acceptedCount();
  std::printf("localization: %zu matches tried, %zu accepted, %zu refused, %zu searches (%zu relocalized); "
              "final state: %s\n",
              attempted_, accepted, localizer.refusedCount(), searches_, localizer.relocalizationCount(),
              stateName(last_state_));
  if (accepted > 0) {
    std::printf("localization: mean inlier share %.3f, mean point-to-plane RMS %.3f m over accepted matches; "
                "%.2f ms a scan on top of the odometry while tracking, %.0f ms a search\n",
                inlier_share_ / accepted, rms_ / accepted, tracked_scans_ > 0 ? milliseconds_ / tracked_scans_ : 0.0,
                searches_ > 0 ? search_milliseconds_ / searches_ : 0.0);
  }
  const double total = odometry_milliseconds_ + milliseconds_;
  if (total > 0.0) {
    std::printf("FPS with localization: %.1f (odometry and map match, over the tracked scans)\n",
                1000.0 * tracked_scans_ / total);
  }
}

}  // namespace elo::tools
