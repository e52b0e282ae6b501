#include "elo/localization/localizer.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <stdexcept>

#include "core/common/map_render.hpp"
#include "core/elapsed_time.hpp"
#include "elo/pipeline/degeneracy.hpp"
#include "elo/pipeline/registration.hpp"

namespace elo {
namespace {

// Gauss-Newton iterations that score a search candidate: from a loose kernel (no informed guess) three
// steps bring a candidate within the correspondence gate of the truth to within centimetres of it, and
// one that is not falls behind in inliers.
constexpr int kCandidateIterations = 3;
// The ground under a hint is looked for within this distance of it (m).
constexpr double kGroundSearchRadius = 3.0;

MapMatchHealth healthOf(const RegistrationResult& registration) {
  const TermSums& nonground = registration.last.nonground;
  const TermSums& ground = registration.last.ground;
  MapMatchHealth health;
  health.failed = registration.failed;
  health.iterations = registration.iterations;
  health.inliers = nonground.inliers + ground.inliers;
  const int candidates = nonground.candidates + ground.candidates;
  health.inlier_share = candidates > 0 ? static_cast<double>(health.inliers) / candidates : 0.0;
  health.rms = health.inliers > 0 ? std::sqrt((nonground.squared_error + ground.squared_error) / health.inliers) : INFINITY;
  return health;
}

// Higher is better: the share of features matched, the residual breaking ties.
bool fitsBetter(const MapMatchHealth& a, const MapMatchHealth& b) {
  if (a.failed != b.failed) return !a.failed;
  if (a.inlier_share != b.inlier_share) return a.inlier_share > b.inlier_share;
  return a.rms < b.rms;
}

// How far pose `b` lies from pose `a`: metres, and degrees of rotation.
struct PoseGap {
  double metres;
  double degrees;
};
PoseGap gapBetween(const Eigen::Isometry3d& a, const Eigen::Isometry3d& b) {
  const Eigen::Isometry3d apart = a.inverse() * b;
  return {apart.translation().norm(), Eigen::AngleAxisd(apart.rotation()).angle() * 180.0 / M_PI};
}

// The offsets the search tries around its hint, in the hint's frame: positions on a square grid within
// `radius`, each at every yaw step within `yaw_deg`; the hint itself first.
std::vector<Eigen::Isometry3d> searchOffsets(const PoseHint& hint, const LocalizationConfig& config) {
  std::vector<Eigen::Isometry3d> offsets;
  const int steps = static_cast<int>(std::floor(hint.radius / config.search_step));
  const int yaw_steps = static_cast<int>(std::floor(hint.yaw_deg / config.search_yaw_step_deg));
  for (int ix = -steps; ix <= steps; ++ix) {
    for (int iy = -steps; iy <= steps; ++iy) {
      const Eigen::Vector3d offset(ix * config.search_step, iy * config.search_step, 0.0);
      if (offset.norm() > hint.radius + 1e-9) continue;
      for (int iyaw = -yaw_steps; iyaw <= yaw_steps; ++iyaw) {
        const double yaw = iyaw * config.search_yaw_step_deg * M_PI / 180.0;
        offsets.push_back(Eigen::Translation3d(offset) * Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitZ()));
      }
    }
  }
  // Nearest first, sorted by index: std::stable_sort's scratch buffer (libstdc++'s temporary buffer) is
  // allocated without the 32-byte alignment an Isometry3d's AVX loads need, and sorting the offsets
  // themselves crashed on Debian 11 (GCC 10, Eigen 3.3).
  std::vector<std::pair<double, size_t>> order;
  order.reserve(offsets.size());
  for (size_t i = 0; i < offsets.size(); ++i) {
    order.emplace_back(offsets[i].translation().norm() + Eigen::AngleAxisd(offsets[i].rotation()).angle(), i);
  }
  std::sort(order.begin(), order.end());  // ties in the offsets' order, as a stable sort leaves them
  std::vector<Eigen::Isometry3d> nearest_first;
  nearest_first.reserve(offsets.size());
  for (const auto& [distance, index] : order) nearest_first.push_back(offsets[index]);
  return nearest_first;
}

std::shared_ptr<const MapCloud> checkedMap(std::shared_ptr<const MapCloud> map) {
  if (!map || map->size() == 0) throw std::invalid_argument("the map is empty");
  if (!map->hasNormals()) throw std::invalid_argument("the map has no normals (prepareMap() estimates them)");
  return map;
}

}  // namespace

const char* stateName(LocalizationState state) {
  switch (state) {
    case LocalizationState::waiting_for_pose:
      return "waiting for an initial pose";
    case LocalizationState::tracking:
      return "tracking";
    case LocalizationState::lost:
      return "lost";
  }
  return "unknown";
}

Localizer::Localizer(Odometry& odometry, std::shared_ptr<const MapCloud> map)
    : odometry_(odometry),
      config_(odometry.config()),
      map_(checkedMap(std::move(map))),
      tiles_(*map_, odometry.config().localization.tile_size) {
  odometry_.backend().setMap(map_);
}

void Localizer::setInitialPose(const Eigen::Isometry3d& map_from_sensor, std::optional<double> radius,
                               std::optional<double> yaw_deg) {
  const LocalizationConfig& config = config_.localization;
  pending_hint_ = PoseHint{map_from_sensor, radius.value_or(config.search_radius), yaw_deg.value_or(config.search_yaw_deg)};
}

double Localizer::sensorHeightAt(const Eigen::Vector2d& xy) const {
  std::vector<int32_t> near;
  tiles_.pointsNear(Eigen::Vector3d(xy.x(), xy.y(), 0.0), kGroundSearchRadius, near);
  std::vector<float> heights;
  for (int32_t point : near) {
    if (std::abs(map_->normals[point].z()) >= kMinMapGroundNormalZ) heights.push_back(map_->points[point].z());
  }
  if (heights.empty()) return NAN;
  // The lower quartile: the road, not a roof or a car's top that lies within the disc.
  std::sort(heights.begin(), heights.end());
  return heights[heights.size() / 4] + config_.ground.sensor_height;
}

size_t Localizer::render(const Eigen::Isometry3d& map_from_sensor, LocalizationResult& result) {
  const auto start = Clock::now();
  nearby_.clear();
  tiles_.pointsNear(map_from_sensor.translation(), config_.localization.render_range, nearby_);
  odometry_.backend().renderMap(nearby_, map_from_sensor);
  result.render_milliseconds += millisecondsSince(start);
  return nearby_.size();
}

Localizer::Match Localizer::registerAgainstMap(const Eigen::Isometry3d& rendered,
                                               const Eigen::Isometry3d& rendered_from_scan, bool informed,
                                               int max_iterations) {
  Backend& backend = odometry_.backend();
  const Linearize linearize = [&backend](const Eigen::Isometry3d& model_from_scan, double kernel_scale) {
    return backend.linearizeMap(model_from_scan, kernel_scale);
  };
  RegistrationConfig registration = config_.registration;
  registration.max_iterations = max_iterations;
  const RegistrationResult result = registerScan(linearize, rendered_from_scan, informed, registration);
  return {rendered * result.model_from_scan, healthOf(result), result.hessian};
}

std::optional<Localizer::SearchOutcome> Localizer::search(const PoseHint& hint, LocalizationResult& result) {
  result.searched = true;
  PoseHint around = hint;
  if (!std::isfinite(around.map_from_sensor.translation().z())) {
    const double z = sensorHeightAt(around.map_from_sensor.translation().head<2>());
    if (!std::isfinite(z)) return std::nullopt;
    around.map_from_sensor.translation().z() = z;
  }
  result.map_points_rendered = render(around.map_from_sensor, result);
  if (result.map_points_rendered == 0) return std::nullopt;
  // Every candidate a few steps, then the best few to convergence.
  std::vector<Match> scored;
  for (const Eigen::Isometry3d& offset : searchOffsets(around, config_.localization)) {
    scored.push_back(registerAgainstMap(around.map_from_sensor, offset, false, kCandidateIterations));
  }
  const size_t refined = std::min<size_t>(scored.size(), static_cast<size_t>(config_.localization.search_refined));
  std::partial_sort(scored.begin(), scored.begin() + refined, scored.end(),
                    [](const Match& a, const Match& b) { return fitsBetter(a.health, b.health); });
  std::vector<Match> converged;
  for (size_t i = 0; i < refined; ++i) {
    const Eigen::Isometry3d from = around.map_from_sensor.inverse() * scored[i].map_from_sensor;
    converged.push_back(registerAgainstMap(around.map_from_sensor, from, false, config_.registration.max_iterations));
  }
  const auto fitter = [](const Match& a, const Match& b) { return fitsBetter(a.health, b.health); };
  const Match& winner = *std::min_element(converged.begin(), converged.end(), fitter);
  SearchOutcome outcome;
  for (const Match& match : converged) {
    if (rivals(match, winner) && (!outcome.rival || fitter(match, *outcome.rival))) outcome.rival = match;
  }
  // The winner registered once more against the map rendered where it stands, as tracking will.
  render(winner.map_from_sensor, result);
  outcome.best = registerAgainstMap(winner.map_from_sensor, Eigen::Isometry3d::Identity(), false,
                                    config_.registration.max_iterations);
  return outcome;
}

bool Localizer::rivals(const Match& rival, const Match& winner) const {
  const LocalizationConfig& config = config_.localization;
  const PoseGap gap = gapBetween(winner.map_from_sensor, rival.map_from_sensor);
  const bool elsewhere = gap.metres > 0.5 * config.search_step || gap.degrees > 0.5 * config.search_yaw_step_deg;
  return elsewhere && rival.health.acceptable(config) &&
         rival.health.inlier_share > winner.health.inlier_share - config.search_margin;
}

void Localizer::accept(const Match& match, LocalizationResult& result) {
  const Eigen::Isometry3d before = map_from_odom_;
  map_from_odom_ = match.map_from_sensor * odometry_.modelPose().inverse();
  result.map_correction = map_from_odom_ * before.inverse();
  // (N H)^-1 scaled by the residual variance: H is the fused J^T J normalised by the inlier counts. The
  // registration's twist lies in the frame the map was rendered in, the sensor's: its axes turned into
  // the map's, as a pose's covariance is given.
  const double variance = match.health.rms * match.health.rms;
  const Matrix6d information = match.hessian * std::max(match.health.inliers, 1) + 1e-9 * Matrix6d::Identity();
  const Matrix6d twist_covariance = variance * information.inverse();
  Matrix6d rotate = Matrix6d::Zero();
  rotate.topLeftCorner<3, 3>() = match.map_from_sensor.rotation();
  rotate.bottomRightCorner<3, 3>() = match.map_from_sensor.rotation();
  covariance_ = rotate * twist_covariance * rotate.transpose();
  state_ = LocalizationState::tracking;
  carried_hint_.reset();
  refused_in_row_ = 0;
  scans_since_match_ = 0;
  ++accepted_;
  result.matched = true;
}

void Localizer::refuse(const std::string& why, LocalizationResult& result) {
  ++refused_;
  ++refused_in_row_;
  result.refusal = why;
  if (state_ == LocalizationState::tracking && refused_in_row_ >= config_.localization.lost_after) {
    state_ = LocalizationState::lost;
    // Searched around from now on: where the odometry puts the vehicle since the last accepted match.
    const LocalizationConfig& config = config_.localization;
    carried_hint_ = CarriedHint{map_from_odom_, config.search_radius, config.search_yaw_deg};
  }
}

void Localizer::track(LocalizationResult& result) {
  const Eigen::Isometry3d predicted = map_from_odom_ * odometry_.modelPose();
  result.map_points_rendered = render(predicted, result);
  if (result.map_points_rendered == 0) return;  // the map has nothing here: the odometry carries the pose
  result.attempted = true;
  const Match match =
      registerAgainstMap(predicted, Eigen::Isometry3d::Identity(), true, config_.registration.max_iterations);
  result.health = match.health;
  const LocalizationConfig& config = config_.localization;
  if (match.health.failed) return refuse("the registration found no usable step", result);
  if (match.health.inlier_share < config.min_inlier_share) return refuse("too few features match the map", result);
  if (match.health.rms > config.max_rms) return refuse("the scan fits the map loosely", result);
  const double correction = (predicted.inverse() * match.map_from_sensor).translation().norm();
  if (correction > config.max_correction) return refuse("the match would move the pose too far", result);
  accept(match, result);
}

Localizer::CarriedHint Localizer::carried(const PoseHint& hint) const {
  // A hint's unknown height (NaN z) stays unknown as it is carried: each search takes it from the map.
  return {hint.map_from_sensor * odometry_.modelPose().inverse(), hint.radius, hint.yaw_deg};
}

std::optional<PoseHint> Localizer::carriedHint() const {
  if (!carried_hint_) return std::nullopt;
  return PoseHint{carried_hint_->map_from_odom * odometry_.modelPose(), carried_hint_->radius, carried_hint_->yaw_deg};
}

void Localizer::relocalize(const PoseHint& hint, LocalizationResult& result) {
  // Until a match is taken, this hint is searched around again as the odometry carries it.
  if (state_ != LocalizationState::tracking) carried_hint_ = carried(hint);
  const std::optional<SearchOutcome> found = search(hint, result);
  result.attempted = found.has_value();
  if (!found) return refuse("no map around the hint", result);
  const Match& best = found->best;
  result.health = best.health;
  if (!best.health.acceptable(config_.localization)) return refuse("no pose around the hint fits the map", result);
  // Where the map leaves a direction free (a tunnel, a featureless road), the search's winner is any of the
  // poses along it: the hint cannot be checked there.
  const std::optional<Degeneracy> degeneracy =
      analyseDegeneracy(best.hessian, config_.registration.degeneracy_threshold);
  if (degeneracy && degeneracy->any()) {
    return refuse("the map here does not fix the pose along " + degeneracy->describe() +
                      ": give a pose where it does",
                  result);
  }
  if (found->rival) {
    const PoseGap gap = gapBetween(best.map_from_sensor, found->rival->map_from_sensor);
    char why[160];
    std::snprintf(why, sizeof why, "another pose %.1f m and %.0f deg away fits the map about as well: give a closer pose",
                  gap.metres, gap.degrees);
    return refuse(why, result);
  }
  accept(best, result);
  ++relocalized_;
}

void Localizer::odometryRestarted() {
  // The odometry started again at the identity: map -> odom, and a carried hint's, now put the new
  // frame's origin where the last scan was, the vehicle having moved little since (time went backwards).
  // That is a guess, not a match: the scan searches around it.
  map_from_odom_ = map_from_odom_ * last_odometry_pose_;
  if (carried_hint_) carried_hint_->map_from_odom = carried_hint_->map_from_odom * last_odometry_pose_;
  last_odometry_pose_ = Eigen::Isometry3d::Identity();
  if (state_ == LocalizationState::waiting_for_pose || pending_hint_) return;
  if (state_ == LocalizationState::tracking) state_ = LocalizationState::lost;
  setInitialPose(map_from_odom_);
}

bool Localizer::searchDue() const {
  return carried_hint_ && scans_since_match_ % config_.localization.lost_after == 0;
}

LocalizationResult Localizer::update(const FrameResult& frame) {
  const auto start = Clock::now();
  LocalizationResult result;
  // A restart is told on the scan that found time going backwards, processed or skipped.
  if (frame.reset) odometryRestarted();
  // A refused registration left the odometry's model and pose where they were: nothing to match.
  if (frame.processed && frame.refusal.empty()) {
    if (pending_hint_) {
      const PoseHint hint = *pending_hint_;
      pending_hint_.reset();
      relocalize(hint, result);
    } else if (state_ == LocalizationState::tracking) {
      track(result);
    } else if (searchDue()) {
      relocalize(*carriedHint(), result);
    }
    if (!result.matched) ++scans_since_match_;
    last_odometry_pose_ = frame.pose;
  }
  result.state = state_;
  result.hint_carried = carried_hint_.has_value();
  result.map_from_odom = map_from_odom_;
  result.pose = map_from_odom_ * frame.pose;
  result.covariance = covariance_;
  result.scans_since_match = scans_since_match_;
  result.milliseconds = millisecondsSince(start);
  return result;
}

}  // namespace elo
