// The start in motion (docs/start_in_motion.md): the motion of a scan registered when none is known yet
// (the first registration after a start, a reset or a restart) searched for before the registration, so
// that odometry started on a vehicle that is already moving (a node restarted on a moving car, a bag cut
// mid-drive) tracks from its second scan.
//
// Without a motion the registration starts from the identity, and a car at 12 m/s has moved 1.2 m:
// beyond the correspondence gate for the surfaces that face the motion, the only ones that tell how far
// it went (facades along the road and the road itself do not). From there the iterations found 0.21 m of
// the 1.22 m on a real KITTI drive and the trajectory stayed a metre behind. The search starts a short
// registration from candidate motions along the sensor's x axis (a vehicle's heading, REP-103), forward
// and back, and in yaw, and keeps the one whose correspondences fit best.
#pragma once

#include <Eigen/Geometry>
#include <vector>

#include "elo/pipeline/backend.hpp"
#include "elo/config.hpp"

namespace elo {

// Where the start search's candidates take their rotation from.
enum class StartRotation {
  search_yaw,  // the centre's, then turned by every yaw step around the best along x
  from_gyro,   // the centre's, the gyro's over the interval: no yaw candidates, translations along x only
};

struct StartSearchResult {
  bool searched = false;
  int candidates = 0;  // candidate motions registered and scored
  StartRotation rotation = StartRotation::search_yaw;
  // T^{t-1}_t the registration starts from: the winning candidate after its short registration.
  Eigen::Isometry3d motion = Eigen::Isometry3d::Identity();
  // The winner's fit: the kernel-weighted share of its non-ground correspondences (fitScore()).
  double score = 0.0;
  // The best candidate that ended elsewhere (more than half a step or a yaw step from the winner): its
  // score, 0 when every candidate ended at the winner's motion.
  double rival_score = 0.0;
  // That rival scored within start_search.margin of the winner: the scan does not tell the motion
  // apart (a featureless road, a repeated structure); the winner is taken and the start counted as
  // ambiguous.
  bool ambiguous = false;
  double milliseconds = 0.0;
};

// How well the scan, moved by the motion `sums` were linearised at, fits the model: the share of the
// non-ground candidates weighted by the robust kernel (the ground's under registration.terms bev_ground).
// With unit normals the trace of J^T W J's translation block is the sum of the kernel weights, which is
// near the inlier count at the right motion and falls off within a kernel scale of it; the plain inlier
// count, under the 1 m correspondence gate, barely tells 0.5 m from the truth.
double fitScore(const NormalEquations& sums, const RegistrationConfig& config);

// A line of candidates along x: around `centre`, the motion a scan `interval` seconds after the model's
// is expected near, within motion.max_speed * `interval` either way.
struct SearchLine {
  Eigen::Isometry3d centre = Eigen::Isometry3d::Identity();
  double interval = 0.0;
};

// Searches the motion of the backend's projected scan against its model: candidates every
// start_search.step metres along x on each line (a candidate within half a step of one tried before is
// not tried again), then (but with the gyro's rotation) at every yaw step within
// start_search.max_yaw_rate_deg times the best candidate's line interval around it, each registered from
// a loose kernel for a few Gauss-Newton steps and scored by fitScore() under the final kernel.
// The lines: around the identity at a start, when no motion was accepted; around the motion accepted
// last carried over the interval when the scan's registration from the prior was refused; after a gap,
// that line and the one of the usual scan interval (the stamps jumped, the sensor did not).
// `rotation` from_gyro: the centres' rotation is the gyro's, and the search tries translations along x
// only (a handheld sensor swung at 190 deg/s turns 19 deg a scan, far beyond the yaw candidates' reach).
StartSearchResult searchStartMotion(Backend& backend, const std::vector<SearchLine>& lines, const Config& config,
                                    StartRotation rotation = StartRotation::search_yaw);

}  // namespace elo
