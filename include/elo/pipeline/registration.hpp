// Gauss-Newton point-to-plane ICP on SE(3) over the fused cost w*E_S + (1-w)*E_G (Sec. III-A).
#pragma once

#include <functional>

#include "elo/pipeline/backend.hpp"
#include "elo/pipeline/degeneracy.hpp"

namespace elo {

struct RegistrationResult {
  Eigen::Isometry3d model_from_scan = Eigen::Isometry3d::Identity();  // T^{t-1}_t
  Matrix6d hessian = Matrix6d::Zero();  // the fused, normalised J^T J at the solution
  int iterations = 0;
  bool converged = false;
  // No usable step: too few correspondences or a singular Hessian. model_from_scan then holds the last
  // estimate that had one (the initial guess when the first iteration failed).
  bool failed = false;
  double weight = 0.0;  // w = w1 * w2 of the last iteration
  NormalEquations last;  // the sums of the last iteration (inlier counts, errors)
  // The directions the scan does not constrain (registration.degeneracy_threshold), decided at the
  // initial guess, with the scaled eigenvalues of the Hessian that decided (see registration.cpp). Along
  // a degenerate direction the estimate is the initial guess's.
  Degeneracy degeneracy;
};

// w = w1 * w2. w2 compares the inlier ratios of the two terms: 1 while non-ground matching is at least
// as good as ground matching, and falling with the non-ground ratio when it is worse, so that w stays
// in [0, w1] and the ground term takes over where the non-ground scene degrades (highway).
double fusionWeight(const NormalEquations& sums, const RegistrationConfig& config);

// Builds H = w/N_S sum J_S^T J_S + (1-w)/N_G sum J_G^T J_G and g likewise, each term normalised by its
// inlier count so that w keeps its meaning whatever the point counts.
void fuseNormalEquations(const NormalEquations& sums, double weight, Matrix6d& H, Vector6d& g);

// The scale of the robust kernel over the iterations. Without an informed initial guess it starts at the
// correspondence gate and halves each iteration down to `robust_kernel_scale`, jumping to the final one
// once the steps become small; with one it starts at the final scale. A tight kernel from the start would
// ignore the very residuals a poor initial guess produces: a start at 10 m/s is a metre from the
// identity guess, mostly along facades that constrain it only through a few surfaces facing the motion
// (test/pipeline/test_fault_drives.cpp). A tight kernel at the end keeps edge correspondences from
// biasing the solution.
class KernelSchedule {
 public:
  KernelSchedule(const RegistrationConfig& config, bool informed_guess);
  double scale() const { return scale_; }
  bool isFinal() const { return scale_ == final_; }
  // Moves to the next iteration's scale; returns true when a small step under the final scale ends the
  // registration.
  bool advance(bool step_was_small);

 private:
  double final_;
  double scale_;
};

// Offered the estimate `model_from_scan` after every Gauss-Newton step taken under the final kernel scale,
// before that step's convergence ends the registration (`converged`): it may move the scan's points
// (deskew them again under the motion estimated so far, docs/deskew.md) and return true, and the
// registration goes on from there until a step converges; false leaves the registration as it was.
// Offered before convergence, a refresh costs no iterations of its own: the steps still to come serve
// both the estimate and the moved points.
using ScanRefresh = std::function<bool(const Eigen::Isometry3d& model_from_scan, bool converged)>;

// `informed_guess`: the initial guess comes from a motion model with enough history to trust it. The
// steps then solve only the directions the scan constrains (see degeneracy.hpp); along the others the
// estimate keeps the initial guess. Without an informed guess every direction is solved.
RegistrationResult registerScan(Backend& backend, const Eigen::Isometry3d& initial_guess, bool informed_guess,
                                const RegistrationConfig& config, const ScanRefresh& refresh = {});

// The sums of one Gauss-Newton step (Backend::linearize() or Backend::linearizeMap()).
using Linearize = std::function<NormalEquations(const Eigen::Isometry3d& model_from_scan, double kernel_scale)>;
// The same loop over any model the scan is linearised against: localization registers the scan against
// the map model (Backend::linearizeMap()) with it.
RegistrationResult registerScan(const Linearize& linearize, const Eigen::Isometry3d& initial_guess,
                                bool informed_guess, const RegistrationConfig& config, const ScanRefresh& refresh = {});

}  // namespace elo
