#include "elo/pipeline/tracking_guard.hpp"

#include <cmath>
#include <vector>

#include "core/median.hpp"

namespace elo {
namespace {

// Accepted registrations whose inliers a new one is held against: a second of scans at 10 Hz, so that a
// scene that changes as the vehicle drives on (a street opening into a square) is followed.
constexpr size_t kRecentRegistrations = 10;
// Fewer than this many recent registrations tell no collapse.
constexpr size_t kFewestRecentForCollapse = 3;

}  // namespace

int TrackingGuard::sceneInliers(const RegistrationResult& registration) const {
  return terms_ == CostTerms::bev_ground ? registration.last.ground.inliers : registration.last.nonground.inliers;
}

std::string TrackingGuard::refusal(const RegistrationResult& registration, double dt) const {
  if (registration.failed) return refusal::kFailed;
  if (!(dt > 0.0)) return {};
  const Eigen::Isometry3d& motion = registration.model_from_scan;
  if (motion.translation().norm() / dt > config_.max_speed) return refusal::kTooFast;
  const double turn_deg = Eigen::AngleAxisd(motion.rotation()).angle() * 180.0 / M_PI;
  if (turn_deg / dt > config_.max_turn_rate_deg) return refusal::kTurnsTooFast;
  if (previous_velocity_) {
    const Vector6d velocity = logSE3(motion) / dt;
    const double change = (velocity.head<3>() - previous_velocity_->head<3>()).norm();
    const double stamp_error_share = 2.0 * config_.stamp_jitter / dt;
    if (change > config_.max_acceleration * dt + stamp_error_share * previous_velocity_->head<3>().norm()) {
      return refusal::kAccelerates;
    }
  }
  if (recent_inliers_.size() >= kFewestRecentForCollapse) {
    const int median = upperMedian(std::vector<int>(recent_inliers_.begin(), recent_inliers_.end()));
    if (sceneInliers(registration) < config_.min_inlier_share_of_recent * median) {
      return refusal::kInliersCollapsed;
    }
  }
  return {};
}

void TrackingGuard::accept(const RegistrationResult& registration, double dt) {
  if (dt > 0.0) previous_velocity_ = logSE3(registration.model_from_scan) / dt;
  recent_inliers_.push_back(sceneInliers(registration));
  if (recent_inliers_.size() > kRecentRegistrations) recent_inliers_.pop_front();
}

}  // namespace elo
