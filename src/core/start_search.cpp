#include "elo/pipeline/start_search.hpp"

#include <algorithm>
#include <cmath>
#include <vector>

#include "core/elapsed_time.hpp"
#include "elo/pipeline/registration.hpp"

namespace elo {
namespace {

// Gauss-Newton steps a candidate is registered for before it is scored: from the loose kernel the three
// bring a candidate within about half a step of the motion to within centimetres of it, while one farther
// off stays where the surfaces facing the motion do not fit.
constexpr int kCandidateIterations = 3;
// Candidates either way at most, along x and in yaw: a scan long after the model's (dropped scans right
// after a start) is searched over this many steps, not over its whole max_speed * dt.
constexpr int kMaxStepsEachWay = 20;

struct Candidate {
  Eigen::Isometry3d motion;
  double score;
};

// Steps of `step` within `reach` either side of zero, at most `limit` each way: -n..n.
int stepsWithin(double reach, double step, int limit) {
  // Compared as doubles: a reach of many steps (a bound set very high) must not overflow the int.
  return static_cast<int>(std::min<double>(limit, std::floor(reach / step + 1e-9)));
}

// 0, -1, 1, -2, 2, ... -n, n: the offsets of a line of candidates, nearest the centre first.
std::vector<int> offsetsWithin(int n) {
  std::vector<int> offsets{0};
  for (int i = 1; i <= n; ++i) offsets.insert(offsets.end(), {-i, i});
  return offsets;
}

// A candidate along x: its motion and the line it lies on.
struct AlongX {
  Eigen::Isometry3d motion;
  int line;
};

// Candidates along x every step within motion.max_speed * interval either way of each line's centre, each
// centre first; one within half a step of a candidate before it is left out (the lines after a gap
// overlap when the vehicle was slow).
std::vector<AlongX> motionsAlongX(const std::vector<SearchLine>& lines, const Config& config) {
  const StartSearchConfig& search = config.start_search;
  std::vector<AlongX> motions;
  const auto tried = [&](const Eigen::Isometry3d& motion) {
    return std::any_of(motions.begin(), motions.end(), [&](const AlongX& before) {
      return (before.motion.translation() - motion.translation()).norm() < 0.5 * search.step;
    });
  };
  for (size_t line = 0; line < lines.size(); ++line) {
    const double reach = config.motion.max_speed * lines[line].interval;
    for (int offset : offsetsWithin(stepsWithin(reach, search.step, kMaxStepsEachWay))) {
      Eigen::Isometry3d motion = lines[line].centre;
      motion.translation().x() += offset * search.step;
      if (!tried(motion)) motions.push_back({motion, static_cast<int>(line)});
    }
  }
  return motions;
}

// `centre` turned by every yaw step within `yaw_reach` (rad) either way, `centre` itself left out.
std::vector<Eigen::Isometry3d> yawsAround(const Eigen::Isometry3d& centre, double yaw_reach,
                                          const StartSearchConfig& config) {
  const double yaw_step = config.yaw_step_deg * M_PI / 180.0;
  std::vector<Eigen::Isometry3d> motions;
  for (int offset : offsetsWithin(stepsWithin(yaw_reach, yaw_step, kMaxStepsEachWay))) {
    if (offset == 0) continue;
    Eigen::Isometry3d motion = centre;
    motion.linear() = Eigen::AngleAxisd(offset * yaw_step, Eigen::Vector3d::UnitZ()) * centre.linear();
    motions.push_back(motion);
  }
  return motions;
}

Candidate registerCandidate(Backend& backend, const Eigen::Isometry3d& from, const RegistrationConfig& config) {
  RegistrationConfig short_registration = config;
  short_registration.max_iterations = kCandidateIterations;
  const RegistrationResult registered = registerScan(backend, from, false, short_registration);
  const NormalEquations fit = backend.linearize(registered.model_from_scan, config.robust_kernel_scale);
  return {registered.model_from_scan, registered.failed ? 0.0 : fitScore(fit, config)};
}

bool endedElsewhere(const Eigen::Isometry3d& a, const Eigen::Isometry3d& b, const StartSearchConfig& config) {
  const Eigen::Isometry3d apart = a.inverse() * b;
  const double degrees = Eigen::AngleAxisd(apart.rotation()).angle() * 180.0 / M_PI;
  return apart.translation().norm() > 0.5 * config.step || degrees > 0.5 * config.yaw_step_deg;
}

}  // namespace

double fitScore(const NormalEquations& sums, const RegistrationConfig& config) {
  const TermSums& term = config.terms == CostTerms::bev_ground ? sums.ground : sums.nonground;
  if (term.candidates == 0) return 0.0;
  return term.JtJ.topLeftCorner<3, 3>().trace() / term.candidates;
}

StartSearchResult searchStartMotion(Backend& backend, const std::vector<SearchLine>& lines, const Config& config,
                                    StartRotation rotation) {
  const auto start = Clock::now();
  const StartSearchConfig& search = config.start_search;
  // Along x first, then in yaw around where the best along x started: a turn within the search's yaw
  // reach hardly moves where the scan fits along x, so the two are searched one after the other rather
  // than on a grid of both, at a third of its cost. The gyro's rotation is good to a small fraction of a
  // yaw step (a bias of 0.5 deg/s turns 0.05 deg a scan), so centred on it the yaw candidates add nothing.
  const std::vector<AlongX> along_x = motionsAlongX(lines, config);
  std::vector<Candidate> scored;
  for (const AlongX& candidate : along_x) {
    scored.push_back(registerCandidate(backend, candidate.motion, config.registration));
  }
  const auto better = [](const Candidate& a, const Candidate& b) { return a.score > b.score; };
  if (rotation == StartRotation::search_yaw) {
    const size_t best_along_x = std::min_element(scored.begin(), scored.end(), better) - scored.begin();
    const double interval = lines[along_x[best_along_x].line].interval;
    const double yaw_reach = search.max_yaw_rate_deg * M_PI / 180.0 * interval;
    for (const Eigen::Isometry3d& motion : yawsAround(along_x[best_along_x].motion, yaw_reach, search)) {
      scored.push_back(registerCandidate(backend, motion, config.registration));
    }
  }
  const Candidate winner = *std::min_element(scored.begin(), scored.end(), better);
  StartSearchResult result;
  result.searched = true;
  result.rotation = rotation;
  result.candidates = static_cast<int>(scored.size());
  result.motion = winner.motion;
  result.score = winner.score;
  for (const Candidate& candidate : scored) {
    if (endedElsewhere(winner.motion, candidate.motion, search)) {
      result.rival_score = std::max(result.rival_score, candidate.score);
    }
  }
  result.ambiguous = result.rival_score > 0.0 && result.rival_score >= winner.score - search.margin;
  result.milliseconds = millisecondsSince(start);
  return result;
}

}  // namespace elo
