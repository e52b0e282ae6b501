// Localization on a saved map with the odometry's own engine (docs/localization.md). After each scan the
// odometry processed, the map around the predicted pose is rendered into a second model of the backend
// (Backend::renderMap()) and the scan's features, extracted once for both, register against it with the
// ELO cost and Gauss-Newton loop. An accepted match corrects map -> odom; between matches, and whenever
// the map has nothing to offer, the odometry carries the pose, so map -> sensor stays smooth (REP-105).
#pragma once

#include <Eigen/Geometry>
#include <memory>
#include <optional>
#include <string>

#include "elo/map/point_map.hpp"
#include "elo/pipeline/odometry.hpp"

namespace elo {

enum class LocalizationState {
  waiting_for_pose,  // no pose in the map yet: give one (setInitialPose()); a refused one is searched again
  tracking,          // matches are accepted; map -> odom follows them
  lost,              // lost_after matches in a row refused: the pose is the odometry's since the last accepted one
};
const char* stateName(LocalizationState state);

// How well a scan fits the map at a registered pose.
struct MapMatchHealth {
  double inlier_share = 0.0;  // of the scan's features (both terms), those with a map correspondence
  double rms = 0.0;           // m: point-to-plane RMS over those correspondences
  int inliers = 0;
  int iterations = 0;
  bool failed = false;  // the registration found no usable step

  // Whether `config` accepts a match this healthy.
  bool acceptable(const LocalizationConfig& config) const {
    return !failed && inlier_share >= config.min_inlier_share && rms <= config.max_rms;
  }
};

// A pose hint and how far around it the search looks.
struct PoseHint {
  Eigen::Isometry3d map_from_sensor = Eigen::Isometry3d::Identity();
  double radius = 0.0;   // m
  double yaw_deg = 0.0;  // either side
};

struct LocalizationResult {
  LocalizationState state = LocalizationState::waiting_for_pose;
  bool attempted = false;    // a map match was tried on this scan
  bool matched = false;      // and accepted: map -> odom was corrected by it
  bool searched = false;     // an initial-pose search ran on this scan
  // Not tracking, with a hint the odometry carries: a search around it runs every lost_after scans.
  bool hint_carried = false;
  std::string refusal;       // why a tried match was not accepted
  MapMatchHealth health;     // of the match tried on this scan
  Eigen::Isometry3d map_from_odom = Eigen::Isometry3d::Identity();
  // The sensor in the map at the scan's stamp. While waiting for a pose, the odometry's (from its first
  // scan, carried across its restarts): the first accepted match's map_correction places those in the map.
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
  // How this scan's accepted match moved map -> odom: a pose reported before it, P, lies at
  // map_correction * P in the map as corrected (the identity when no match was accepted).
  Eigen::Isometry3d map_correction = Eigen::Isometry3d::Identity();
  // Of `pose`, (x y z, rotation about x y z) in the sensor frame, from the last accepted match's
  // Hessian and residuals, grown by nothing between matches (a figure of the fit, not of drift).
  Matrix6d covariance = Matrix6d::Identity();
  int scans_since_match = 0;
  size_t map_points_rendered = 0;
  double milliseconds = 0.0;  // the localization's own time on this scan (render, registration, search)
  double render_milliseconds = 0.0;  // of it, rendering the map
};

class Localizer {
 public:
  // Localizes `odometry`'s scans in `map` (prepared: with normals). Throws std::invalid_argument for an
  // empty map or one without normals. update() throws std::runtime_error when the backend cannot render
  // the map near the vehicle (the CUDA backend: that part of the map does not fit in the device's free
  // memory).
  Localizer(Odometry& odometry, std::shared_ptr<const MapCloud> map);

  // The sensor's pose in the map near the next scan: that scan searches around it (localization.search_*
  // unless `radius` / `yaw_deg` are given) and takes the best match only if it is acceptable. A hint's z
  // that is NaN (rviz's 2D Pose Estimate has none) is taken from the map's ground under it. A refused hint
  // is not dropped while no match is being accepted: the odometry carries it, and the search around it
  // runs again every localization.lost_after scans until one is taken or another hint replaces it (a
  // pose given in a tunnel, or before the vehicle enters the map, is taken where the map fixes it).
  void setInitialPose(const Eigen::Isometry3d& map_from_sensor, std::optional<double> radius = std::nullopt,
                      std::optional<double> yaw_deg = std::nullopt);

  // Localizes the scan `odometry.process()` just returned `frame` for. A frame whose odometry restarted
  // (FrameResult::reset) calls odometryRestarted() first.
  LocalizationResult update(const FrameResult& frame);

  // The odometry started a new trajectory at the identity (Odometry::reset()): map -> odom no longer
  // holds. The new frame is put where the last scan was in the map, the vehicle having moved little, and
  // (once a pose was found) the next scan searches around it.
  void odometryRestarted();

  // While not tracking: the hint the odometry carries (the last one refused or, once lost, the pose since
  // the last accepted match), where it puts the last scan processed. nullopt while tracking or with no hint.
  std::optional<PoseHint> carriedHint() const;

  LocalizationState state() const { return state_; }
  const Eigen::Isometry3d& mapFromOdom() const { return map_from_odom_; }
  const MapCloud& map() const { return *map_; }
  size_t acceptedCount() const { return accepted_; }
  size_t refusedCount() const { return refused_; }
  size_t relocalizationCount() const { return relocalized_; }

  // The map's height (z) under `xy` plus the sensor's height above the ground: where a sensor standing
  // there would be. NaN where the map has no ground within a few metres.
  double sensorHeightAt(const Eigen::Vector2d& xy) const;

 private:
  struct Match {
    Eigen::Isometry3d map_from_sensor;  // the scan's reference frame registered in the map
    MapMatchHealth health;
    Matrix6d hessian = Matrix6d::Zero();
  };
  // Renders the map around `map_from_sensor` into the backend's map model, timed into `result`; the
  // number of points rendered.
  size_t render(const Eigen::Isometry3d& map_from_sensor, LocalizationResult& result);
  // Registers the scan against the rendered map from `rendered_from_scan`.
  Match registerAgainstMap(const Eigen::Isometry3d& rendered, const Eigen::Isometry3d& rendered_from_scan,
                           bool informed, int max_iterations);
  // What a search found: its winner, registered again where it stands, and a rival: the best acceptable
  // candidate that converged elsewhere and fits about as well (localization.search_margin), if any.
  struct SearchOutcome {
    Match best;
    std::optional<Match> rival;
  };
  // The search around `hint` for the scan's reference frame; nullopt where the map has nothing there.
  std::optional<SearchOutcome> search(const PoseHint& hint, LocalizationResult& result);
  // Whether `rival`, refined from the same rendering as `winner`, is another place that fits about as well.
  bool rivals(const Match& rival, const Match& winner) const;
  void track(LocalizationResult& result);
  void relocalize(const PoseHint& hint, LocalizationResult& result);
  // A hint the odometry carries between searches: its map -> odom, and how wide it is searched.
  struct CarriedHint {
    Eigen::Isometry3d map_from_odom;
    double radius;
    double yaw_deg;
  };
  // `hint`, given for the scan just processed, carried on by the odometry.
  CarriedHint carried(const PoseHint& hint) const;
  // Whether this scan searches around the carried hint: every lost_after scans while not tracking.
  bool searchDue() const;
  void accept(const Match& match, LocalizationResult& result);
  void refuse(const std::string& why, LocalizationResult& result);

  Odometry& odometry_;
  Config config_;
  std::shared_ptr<const MapCloud> map_;
  MapTiles tiles_;
  std::vector<int32_t> nearby_;
  LocalizationState state_ = LocalizationState::waiting_for_pose;
  Eigen::Isometry3d map_from_odom_ = Eigen::Isometry3d::Identity();
  std::optional<PoseHint> pending_hint_;
  // While not tracking: the refused hint, or, once lost, the pose the odometry carries from the last match.
  std::optional<CarriedHint> carried_hint_;
  Eigen::Isometry3d last_odometry_pose_ = Eigen::Isometry3d::Identity();  // the last processed scan's
  Matrix6d covariance_ = Matrix6d::Identity();
  int refused_in_row_ = 0;
  int scans_since_match_ = 0;
  size_t accepted_ = 0;
  size_t refused_ = 0;
  size_t relocalized_ = 0;
};

}  // namespace elo
