// elo_run --localize: the map loaded and prepared, the initial pose parsed, each scan localized after the
// odometry processed it, and a summary of the matches. Kept apart from elo_run's scan loop.
#pragma once

#include <cmath>
#include <cstdio>
#include <memory>
#include <sstream>
#include <string>
#include <vector>

#include "command_line.hpp"
#include "elo/io/map_pcd.hpp"
#include "elo/localization/localizer.hpp"

namespace elo::tools {

// "x y z yaw_deg" (commas allowed): the sensor's pose in the map at the first scan. A z of "nan" takes
// the height from the map's ground under x, y.
inline Eigen::Isometry3d parseInitialPose(std::string text) {
  for (char& c : text) {
    if (c == ',') c = ' ';
  }
  std::istringstream stream(text);
  std::vector<double> values;
  std::string item;
  while (stream >> item) values.push_back(parseNumber<double>("--initial-pose", item));
  if (values.size() != 4 || !std::isfinite(values[0]) || !std::isfinite(values[1]) || !std::isfinite(values[3])) {
    throw UsageError("--initial-pose expects \"x y z yaw_deg\", got '" + text + "'");
  }
  return Eigen::Translation3d(values[0], values[1], values[2]) *
         Eigen::AngleAxisd(values[3] * M_PI / 180.0, Eigen::Vector3d::UnitZ());
}

// Reads and prepares the map at `path` (normals estimated when it has none), saying what that did.
inline std::shared_ptr<const MapCloud> loadMap(const std::string& path, const Config& config) {
  size_t non_finite_skipped = 0;
  MapCloud map = readMapPcd(path, &non_finite_skipped);
  MapPreparation preparation = prepareMap(map, config.localization.normal_radius);
  preparation.non_finite_dropped += non_finite_skipped;  // the reader's skips: prepareMap() found none left
  std::fprintf(stderr, "map %s: %zu points", path.c_str(), map.size());
  if (preparation.non_finite_dropped > 0) std::fprintf(stderr, ", %zu non-finite dropped", preparation.non_finite_dropped);
  if (preparation.bad_normals > 0) std::fprintf(stderr, ", %zu normals not unit vectors (dropped)", preparation.bad_normals);
  if (preparation.estimated) std::fprintf(stderr, ", normals estimated (%zu fitted)", preparation.normals_estimated);
  std::fprintf(stderr, "\n");
  return std::make_shared<const MapCloud>(std::move(map));
}

// The poses written before the first accepted match are the odometry's, there being no pose in the map
// yet; that match's correction places them in the map, so that the output is in the map frame throughout.
class PosesBeforeTheFirstMatch {
 public:
  // Appends `result`'s pose to `poses`, and places the waiting ones once a match is accepted.
  void add(const LocalizationResult& result, std::vector<Eigen::Isometry3d>& poses) {
    poses.push_back(result.pose);
    if (result.state == LocalizationState::waiting_for_pose) {
      waiting_.push_back(poses.size() - 1);
      return;
    }
    if (!result.matched || waiting_.empty()) return;
    for (size_t line : waiting_) poses[line] = result.map_correction * poses[line];
    placed_ = waiting_.size();
    waiting_.clear();
  }
  // Says which poses were placed after the fact, or are not in the map frame at all.
  void print() const {
    if (placed_ > 0) {
      std::printf("localization: the %zu scans before the first accepted match were placed in the map by it\n", placed_);
    }
    if (!waiting_.empty()) {
      std::fprintf(stderr, "warning: no pose in the map was found: the %zu poses written while waiting for one are "
                   "the odometry's, in the frame of its first scan\n", waiting_.size());
    }
  }

 private:
  std::vector<size_t> waiting_;  // lines of `poses` written while waiting for a pose
  size_t placed_ = 0;
};

// Counts what the localizer did over the run.
class LocalizationReport {
 public:
  // `odometry_ms`: the odometry's time on the same scan (FrameResult::times.total).
  void add(const LocalizationResult& result, double odometry_ms) {
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
  void print(const Localizer& localizer) const {
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

 private:
  size_t attempted_ = 0;
  size_t searches_ = 0;
  double milliseconds_ = 0.0;  // the localization's, over the tracked scans
  double odometry_milliseconds_ = 0.0;  // over the tracked scans
  double search_milliseconds_ = 0.0;
  size_t tracked_scans_ = 0;
  double inlier_share_ = 0.0;
  double rms_ = 0.0;
  LocalizationState last_state_ = LocalizationState::waiting_for_pose;
};

}  // namespace elo::tools
