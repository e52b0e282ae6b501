#include "elo/registration.hpp"

#include <Eigen/Cholesky>
#include <algorithm>

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
                            : std::min(config.max_correspondence_distance,
                                       kStartFactor * config.robust_kernel_scale)) {}

bool KernelSchedule::advance(bool step_was_small) {
  if (step_was_small) {
    if (isFinal()) return true;
    scale_ = final_;  // converged under a loose kernel: refine under the final one at once
  } else {
    scale_ = std::max(final_, 0.5 * scale_);
  }
  return false;
}

RegistrationResult registerScan(Backend& backend, const Eigen::Isometry3d& initial_guess, bool informed_guess,
                                const RegistrationConfig& config) {
  RegistrationResult result;
  result.model_from_scan = initial_guess;
  KernelSchedule kernel(config, informed_guess);
  Vector6d g;
  for (int iteration = 0; iteration < config.max_iterations; ++iteration) {
    result.last = backend.linearize(result.model_from_scan, kernel.scale());
    result.weight = fusionWeight(result.last, config);
    fuseNormalEquations(result.last, result.weight, result.hessian, g);
    result.iterations = iteration + 1;
    const Eigen::LDLT<Matrix6d> solver(result.hessian);
    // Fewer than six constraints, or a Hessian that is not positive definite, give no step to trust.
    if (result.last.nonground.inliers + result.last.ground.inliers < 6 || solver.info() != Eigen::Success ||
        !solver.isPositive()) {
      result.failed = true;
      return result;
    }
    const Vector6d step = -solver.solve(g);
    if (!step.allFinite()) {
      result.failed = true;
      return result;
    }
    result.model_from_scan = expSE3(step) * result.model_from_scan;
    const bool small = step.head<3>().norm() < config.converged_translation &&
                       step.tail<3>().norm() < config.converged_rotation;
    if (kernel.advance(small)) {
      result.converged = true;
      break;
    }
  }
  return result;
}

}  // namespace elo
