// A lost track told and recovered (docs/robustness.md#a-lost-track): every registration is checked
// against what the platform can do (MotionConfig: speed, turn rate, the change of velocity since the
// registration before) and against the registrations before it (inliers that collapse: a scan of another
// place, a blocked view). Odometry refuses one that fails: its pose is the motion prior's, it updates
// neither the model nor the velocity, and the next scan's motion is searched as at a start.
#pragma once

#include <deque>
#include <optional>
#include <string>

#include "elo/config.hpp"
#include "elo/pipeline/registration.hpp"

namespace elo {

// The reasons a registration is refused, as Odometry counts them.
namespace refusal {
constexpr const char* kFailed = "registration failed";
constexpr const char* kTooFast = "faster than motion.max_speed";
constexpr const char* kTurnsTooFast = "turning faster than motion.max_turn_rate_deg";
constexpr const char* kAccelerates = "velocity changed beyond motion.max_acceleration";
constexpr const char* kInliersCollapsed = "inliers collapsed against the scans before";
}  // namespace refusal

class TrackingGuard {
 public:
  explicit TrackingGuard(const Config& config) : config_(config.motion), terms_(config.registration.terms) {}

  // Why `registration`, the motion T^{t-1}_t between the model's scan and one `dt` seconds later, cannot
  // be the platform's (one of the refusal:: reasons), or empty when it can. Its velocity is held against
  // the one accepted last, however many registrations were refused since: a wrong motion found after a
  // refusal is refused as well, until the model restarts (Odometry, motion.restart_after).
  std::string refusal(const RegistrationResult& registration, double dt) const;
  // Records an accepted registration over `dt`: its velocity and inliers, which the next ones are held
  // against.
  void accept(const RegistrationResult& registration, double dt);
  // Forgets the velocity accepted last: the next registration (after a gap) is not held against it.
  void forgetVelocity() { previous_velocity_.reset(); }
  // Forgets them: the model restarted, or the scan follows a gap (Odometry::followGap()), and what it
  // gives is not held against what came before.
  void reset() {
    recent_inliers_.clear();
    previous_velocity_.reset();
  }

 private:
  // The scene's inliers: the non-ground term's, as flat ground matches flat ground anywhere (the
  // ground's under registration.terms bev_ground).
  int sceneInliers(const RegistrationResult& registration) const;

  MotionConfig config_;
  CostTerms terms_;
  std::deque<int> recent_inliers_;  // of the last accepted registrations, the newest last
  std::optional<Vector6d> previous_velocity_;  // twist per second of the last accepted registration
};

}  // namespace elo
