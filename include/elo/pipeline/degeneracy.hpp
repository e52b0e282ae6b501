// Degeneracy of a registration (Zhang, Kaess & Singh, "On Degeneracy of Optimization-based State
// Estimation Problems", ICRA 2016): the directions of motion a scan does not constrain (along a long
// tunnel, along a featureless motorway), read from the eigen-decomposition of the Gauss-Newton Hessian,
// and the step that fades along them into the motion prior as their share of the constraint falls: the
// prior holds information tau^4 / lambda^3 along an eigen direction of share lambda (tau the threshold),
// so the scan decides lambda^4 / (lambda^4 + tau^4) of the estimate there. Well-constrained directions
// are the scan's (94% at lambda = 2 tau, 99.99% at 10 tau), degenerate ones the prior's (6% at tau / 2,
// 0.01% at tau / 10), and no threshold makes an edge between them (issue 31).
//
// The raw Hessian mixes units: the translation rows of the Jacobian are the normal n (dimensionless), the
// rotation rows p x n carry the point's lever arm (m). Its eigenvalues compare m^0 with m^2, and a
// threshold on them would depend on how far away the walls are. So the analysis scales the rotation part
// by the RMS lever arm of the correspondences, L = sqrt(tr H_rr / tr H_tt), and divides by tr H_tt: both
// diagonal blocks then have trace 1, and an eigenvalue is the share of the constraint along its direction.
// For a pure translation d it is the mean of (n . d)^2 over the correspondences (weighted as H is); for a
// pure rotation about a, the share of their squared moments about a. An isotropic scene gives 1/3 for each
// of the six; the eigenvalues sum to 2. In a straight tunnel the forward translation gets only what
// normal noise leaves (measured in the README, Degeneracy). The full 6x6 is decomposed, not the two blocks
// apart, because in a curving tunnel the unobservable motion is a screw (forward translation with yaw)
// that neither block shows alone.
#pragma once

#include <optional>
#include <string>

#include "elo/se3.hpp"

namespace elo {

struct Degeneracy {
  Vector6d eigenvalues = Vector6d::Zero();       // of the scaled Hessian, ascending
  Matrix6d eigenvectors = Matrix6d::Identity();  // matching unit columns, in scaled twist coordinates
  double lever_arm = 1.0;                        // L (m): the RMS lever arm of the correspondences
  double threshold = 0.0;                        // tau: the share at which the scan and the prior weigh alike
  int count = 0;  // eigenvalues under the threshold: the first `count` eigenvectors are degenerate

  bool any() const { return count > 0; }
  // The share of the estimate the scan decides along each eigen direction, lambda^4 / (lambda^4 + tau^4):
  // 1 with the handling off (tau 0).
  Vector6d measuredShares() const;
  // The part of a twist (translation m, rotation rad) that the prior holds: each eigen component scaled by
  // 1 - its measured share, in scaled coordinates (translation m, rotation times L: the arc it sweeps at L).
  // A projector onto the degenerate directions as their shares fall to 0.
  Matrix6d priorShare() const;
  // The covariance of the estimated twist: `measurement_scale` * `hessian`^-1 within the constrained
  // directions (the residual variance over the inlier count), and `prior_variance` (m^2 in scaled
  // coordinates) along each degenerate one, where the estimate is the prior's.
  Matrix6d covariance(const Matrix6d& hessian, double measurement_scale, double prior_variance) const;
  // The sensor-frame axes each degenerate direction is made of, e.g. "x" along a straight tunnel or
  // "x+yaw" along a curving one; directions separated by "; ", empty when there is none.
  std::string describe() const;
};

// Decomposes the fused Hessian and counts the eigenvalues under `threshold` (0: none is degenerate).
// Nullopt when H constrains no translation or no rotation at all.
std::optional<Degeneracy> analyseDegeneracy(const Matrix6d& hessian, double threshold);

// The Gauss-Newton step that minimises the linearised cost H, g plus the motion prior's: information
// tau^4 / lambda^3 (times H's translation trace, in scaled coordinates) along each eigen direction of
// `degeneracy` (which may come from another Hessian than `hessian`), about the prior's estimate, from
// which the current one lies `from_prior` (log of estimate * prior^-1). With the handling off it is
// -H^-1 g. Nullopt when the system is not positive definite.
std::optional<Vector6d> priorWeightedStep(const Degeneracy& degeneracy, const Matrix6d& hessian,
                                          const Vector6d& gradient, const Vector6d& from_prior);

}  // namespace elo
