#include "elo/pipeline/registration.hpp"

#include <algorithm>
#include <cmath>
#include <optional>

namespace elo {

TermSums& TermSums::operator+=(const TermSums& other) {
  JtJ += other.JtJ;
  Jte += other.Jte;
  squared_error += other.squared_error;
  candidates += other.candidates;
  inliers += other.inliers;
  return *this;
}

double fusionWeight(const NormalEquations& sums, const RegistrationConfig& config) {
  switch (config.terms) {
    case CostTerms::spherical_all:
    case CostTerms::spherical_nonground:
      return 1.0;
    case CostTerms::bev_ground:
      return 0.0;
    case CostTerms::fused:
      break;
  }
  // A term without a single inlier cannot be weighed: the other one carries the registration.
  if (sums.ground.inliers == 0) return 1.0;
  if (sums.nonground.inliers == 0) return 0.0;
  const double nonground_ratio = sums.nonground.inlierRatio();
  const double ground_ratio = sums.ground.inlierRatio();
  const double w2 = nonground_ratio >= ground_ratio ? 1.0 : nonground_ratio / ground_ratio;
  return config.nonground_weight * w2;
}

void fuseNormalEquations(const NormalEquations& sums, double weight, Matrix6d& H, Vector6d& g) {
  H.setZero();
  g.setZero();
  if (weight > 0.0 && sums.nonground.inliers > 0) {
    const double scale = weight / sums.nonground.inliers;
    H += scale * sums.nonground.JtJ;
    g += scale * sums.nonground.Jte;
  }
  if (weight < 1.0 && sums.ground.inliers > 0) {
    const double scale = (1.0 - weight) / sums.ground.inliers;
    H += scale * sums.ground.JtJ;
    g += scale * sums.ground.Jte;
  }
}

KernelSchedule::KernelSchedule(const RegistrationConfig& config, bool informed_guess)
    : final_(config.robust_kernel_scale),
      scale_(informed_guess ? config.robust_kernel_scale
                            : std::max(config.max_correspondence_distance, config.robust_kernel_scale)) {}

bool KernelSchedule::advance(bool step_was_small) {
  if (step_was_small) {
    if (isFinal()) return true;
    scale_ = final_;  // converged under a loose kernel: refine under the final one at once
  } else {
    scale_ = std::max(final_, 0.5 * scale_);
  }
  return false;
}

namespace {

// The prior weighs on a direction whose share is under this many thresholds: it holds 10% of the
// estimate there (Degeneracy::measuredShares). Above it the weighted Hessian decides alone.
constexpr double kPriorWeighsBelowThresholds = 3.0;

// The eigen-decomposition that weighs the motion prior against the scan, decided once per scan from the
// first iteration's Hessian `weighted` (linearised at the guess); nullopt when the scene constrains no
// translation or no rotation at all. Keeping it over the iterations keeps the prior's information fixed.
//
// The robust kernel makes the weighted Hessian depend on how far off the guess is: the correspondences
// that would pull along a direction the guess has wrong carry large residuals and little weight, so the
// direction looks degenerate, is kept, stays wrong, and looks degenerate again on the next scan
// (measured: a drive accelerating along a sparse approach road locked at constant velocity and ended
// 75 m behind). A direction on which the prior weighs is therefore confirmed on the geometry alone: the
// unweighted sums of the same correspondences, within the correspondence gate. That costs one
// linearisation more, on those scans only.
std::optional<Degeneracy> priorDirections(const Linearize& linearize, const Eigen::Isometry3d& guess,
                                          const Matrix6d& weighted, double threshold, const RegistrationConfig& config) {
  const std::optional<Degeneracy> flagged = analyseDegeneracy(weighted, threshold);
  if (!flagged || !(flagged->eigenvalues[0] < kPriorWeighsBelowThresholds * threshold)) return flagged;
  const NormalEquations geometry = linearize(guess, 0.0);
  Matrix6d hessian;
  Vector6d unused_gradient;
  fuseNormalEquations(geometry, fusionWeight(geometry, config), hessian, unused_gradient);
  return analyseDegeneracy(hessian, threshold);
}

// The Gauss-Newton step of one iteration, weighed against the motion prior `guess` along the weak
// directions decided on the first; nullopt when there is no step to trust: fewer than six constraints,
// no translation or rotation constraint at all, or a singular system.
std::optional<Vector6d> gaussNewtonStep(const Linearize& linearize, int iteration, const Vector6d& gradient,
                                        const Eigen::Isometry3d& guess, double degeneracy_threshold,
                                        const RegistrationConfig& config, RegistrationResult& result) {
  if (result.last.nonground.inliers + result.last.ground.inliers < 6) return std::nullopt;
  if (iteration == 0) {
    const std::optional<Degeneracy> decided =
        priorDirections(linearize, result.model_from_scan, result.hessian, degeneracy_threshold, config);
    if (!decided) return std::nullopt;
    result.degeneracy = *decided;
  }
  return priorWeightedStep(result.degeneracy, result.hessian, gradient,
                           logSE3(result.model_from_scan * guess.inverse()));
}

// The size of a Gauss-Newton step: its translation (m) and its rotation (rad).
struct StepSize {
  double translation;
  double rotation;
};

// How far the steps still to come move the estimate, after a step of size `now` that followed one of
// size `before` on the same cost: reweighted Gauss-Newton converges linearly, each step a fraction
// rho = now / before of the one before, so the steps to come sum to now rho / (1 - rho). Infinite while
// the steps do not shrink (and with no step before, `before` = 0).
double remainingAfter(double now, double before) { return now < before ? now * now / (before - now) : INFINITY; }

// A component of the motion (translation or rotation) has converged when its step was below the
// tolerance, or when the steps still to come, predicted from how fast the last two shrank, are. A scan
// that converges fast then stops a step earlier; where the steps shrink slowly (rho above 1/2, the
// prediction exceeds the step itself) it stops on the step alone, as without the prediction.
bool componentConverged(double now, double before, double tolerance) {
  return now < tolerance || remainingAfter(now, before) < tolerance;
}

bool hasConverged(const StepSize& step, const std::optional<StepSize>& previous, const RegistrationConfig& config) {
  const StepSize before = previous.value_or(StepSize{0.0, 0.0});
  return componentConverged(step.translation, before.translation, config.converged_translation) &&
         componentConverged(step.rotation, before.rotation, config.converged_rotation);
}

}  // namespace

RegistrationResult registerScan(Backend& backend, const Eigen::Isometry3d& initial_guess, bool informed_guess,
                                const RegistrationConfig& config, const ScanRefresh& refresh) {
  const Linearize linearize = [&backend](const Eigen::Isometry3d& model_from_scan, double kernel_scale) {
    return backend.linearize(model_from_scan, kernel_scale);
  };
  return registerScan(linearize, initial_guess, informed_guess, config, refresh);
}

RegistrationResult registerScan(const Linearize& linearize, const Eigen::Isometry3d& initial_guess,
                                bool informed_guess, const RegistrationConfig& config, const ScanRefresh& refresh) {
  RegistrationResult result;
  result.model_from_scan = initial_guess;
  KernelSchedule kernel(config, informed_guess);
  // Without an informed guess there is no prior worth keeping, and the guess may be a metre off (a start
  // at speed), beyond the correspondence gate along a direction the scene constrains only through a few
  // surfaces. Every direction is solved, as with the handling off.
  const double degeneracy_threshold = informed_guess ? config.degeneracy_threshold : 0.0;
  Vector6d g;
  std::optional<StepSize> previous;  // the last step, while the cost (kernel and scan) stayed the same
  for (int iteration = 0; iteration < config.max_iterations; ++iteration) {
    result.last = linearize(result.model_from_scan, kernel.scale());
    result.weight = fusionWeight(result.last, config);
    fuseNormalEquations(result.last, result.weight, result.hessian, g);
    result.iterations = iteration + 1;
    const std::optional<Vector6d> step =
        gaussNewtonStep(linearize, iteration, g, initial_guess, degeneracy_threshold, config, result);
    if (!step) {
      result.failed = true;
      return result;
    }
    result.model_from_scan = expSE3(*step) * result.model_from_scan;
    const StepSize size{step->head<3>().norm(), step->tail<3>().norm()};
    const double scale = kernel.scale();
    const bool under_final_kernel = kernel.isFinal();
    const bool converged = kernel.advance(hasConverged(size, previous, config));
    if (under_final_kernel && refresh && refresh(result.model_from_scan, converged)) {
      previous.reset();  // the scan's points moved: the next step shrinks on another cost
      continue;
    }
    if (converged) {
      result.converged = true;
      break;
    }
    previous = kernel.scale() == scale ? std::optional<StepSize>(size) : std::nullopt;
  }
  return result;
}

}  // namespace elo
