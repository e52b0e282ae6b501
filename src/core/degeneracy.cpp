#include "elo/pipeline/degeneracy.hpp"

#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>
#include <algorithm>
#include <array>
#include <cmath>
#include <numeric>

namespace elo {
namespace {

// A twist component belongs to a direction's name when it carries at least this share of the unit
// direction (squared, in scaled coordinates): a screw along a curving tunnel reads "x+yaw", a direction
// that is 98% forward translation reads "x".
constexpr double kNamedShare = 0.2;

Vector6d scaling(double lever_arm) {
  Vector6d scale = Vector6d::Ones();
  scale.tail<3>().setConstant(lever_arm);
  return scale;
}

// Along a direction without any share the prior's information is capped here (in shares of the scan's
// translation information t): a pull g of the scan there, which is noise, moves the estimate by g / (1e4 t).
constexpr double kLargestPriorInformation = 1e4;

using ReducedMatrix = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, 0, 6, 6>;

// The Hessian within the constrained directions, in their coordinates: V_c^T D^-1 H D^-1 V_c, where D
// scales twists to scaled coordinates. Its inverse, mapped back, is H^-1 restricted to them.
ReducedMatrix constrainedHessian(const Degeneracy& degeneracy, const Matrix6d& hessian) {
  const Vector6d unscale = scaling(degeneracy.lever_arm).cwiseInverse();
  const auto constrained = degeneracy.eigenvectors.rightCols(6 - degeneracy.count);
  return constrained.transpose() * unscale.asDiagonal() * hessian * unscale.asDiagonal() * constrained;
}

std::string describeDirection(const Vector6d& direction) {
  static const std::array<const char*, 6> kAxes = {"x", "y", "z", "roll", "pitch", "yaw"};
  std::array<int, 6> order;
  std::iota(order.begin(), order.end(), 0);
  std::stable_sort(order.begin(), order.end(),
                   [&](int a, int b) { return std::abs(direction[a]) > std::abs(direction[b]); });
  std::string name;
  for (const int axis : order) {
    if (direction[axis] * direction[axis] < kNamedShare) break;
    name += (name.empty() ? "" : "+") + std::string(kAxes[axis]);
  }
  return name;
}

}  // namespace

Vector6d Degeneracy::measuredShares() const {
  const Eigen::Array<double, 6, 1> fourth = eigenvalues.cwiseMax(0.0).array().square().square();
  return (fourth / (fourth + std::pow(threshold, 4))).matrix();
}

Matrix6d Degeneracy::priorShare() const {
  if (threshold <= 0.0) return Matrix6d::Zero();
  const Vector6d held = Vector6d::Ones() - measuredShares();
  const Vector6d scale = scaling(lever_arm);
  return scale.cwiseInverse().asDiagonal() * (eigenvectors * held.asDiagonal() * eigenvectors.transpose()) *
         scale.asDiagonal();
}

Matrix6d Degeneracy::covariance(const Matrix6d& hessian, double measurement_scale, double prior_variance) const {
  const auto degenerate = eigenvectors.leftCols(count);
  Matrix6d scaled = prior_variance * degenerate * degenerate.transpose();
  if (count < 6) {
    const auto constrained = eigenvectors.rightCols(6 - count);
    scaled += measurement_scale * constrained * constrainedHessian(*this, hessian).inverse() * constrained.transpose();
  }
  const Vector6d unscale = scaling(lever_arm).cwiseInverse();
  return unscale.asDiagonal() * scaled * unscale.asDiagonal();
}

std::string Degeneracy::describe() const {
  std::string text;
  for (int i = 0; i < count; ++i) text += (i > 0 ? "; " : "") + describeDirection(eigenvectors.col(i));
  return text;
}

std::optional<Degeneracy> analyseDegeneracy(const Matrix6d& hessian, double threshold) {
  const double translation_trace = hessian.topLeftCorner<3, 3>().trace();
  const double rotation_trace = hessian.bottomRightCorner<3, 3>().trace();
  if (!(translation_trace > 0.0 && rotation_trace > 0.0) || !std::isfinite(translation_trace + rotation_trace)) {
    return std::nullopt;
  }
  Degeneracy degeneracy;
  degeneracy.lever_arm = std::sqrt(rotation_trace / translation_trace);
  const Vector6d unscale = scaling(degeneracy.lever_arm).cwiseInverse();
  const Matrix6d scaled = unscale.asDiagonal() * hessian * unscale.asDiagonal() / translation_trace;
  const Eigen::SelfAdjointEigenSolver<Matrix6d> solver(scaled);
  if (solver.info() != Eigen::Success) return std::nullopt;
  degeneracy.eigenvalues = solver.eigenvalues();
  degeneracy.eigenvectors = solver.eigenvectors();
  degeneracy.threshold = threshold;
  while (degeneracy.count < 6 && degeneracy.eigenvalues[degeneracy.count] < threshold) ++degeneracy.count;
  return degeneracy;
}

std::optional<Vector6d> priorWeightedStep(const Degeneracy& degeneracy, const Matrix6d& hessian,
                                          const Vector6d& gradient, const Vector6d& from_prior) {
  // In scaled coordinates s = D x (D = diag(1, 1, 1, L, L, L)) the prior adds t V diag(p) V^T to D^-1 H D^-1,
  // t being H's translation trace, so that its information is a share of the scan's whatever the scene:
  // p = tau^4 / lambda^3 against the scan's lambda leaves the scan lambda^4 / (lambda^4 + tau^4).
  const Vector6d unscale = scaling(degeneracy.lever_arm).cwiseInverse();
  Matrix6d system = unscale.asDiagonal() * hessian * unscale.asDiagonal();
  Vector6d right = -(unscale.asDiagonal() * gradient);
  if (degeneracy.threshold > 0.0) {
    const double tau_fourth = std::pow(degeneracy.threshold, 4);
    Vector6d information;
    for (int i = 0; i < 6; ++i) {
      const double share = std::max(degeneracy.eigenvalues[i], 0.0);
      const double cubed = share * share * share;
      information[i] = cubed * kLargestPriorInformation > tau_fourth ? tau_fourth / cubed : kLargestPriorInformation;
    }
    const Matrix6d prior = hessian.topLeftCorner<3, 3>().trace() * degeneracy.eigenvectors *
                           information.asDiagonal() * degeneracy.eigenvectors.transpose();
    system += prior;
    right -= prior * (scaling(degeneracy.lever_arm).asDiagonal() * from_prior);
  }
  const Eigen::LDLT<Matrix6d> solver(system);
  if (solver.info() != Eigen::Success || !(solver.vectorD().array() > 0.0).all()) return std::nullopt;
  const Vector6d step = unscale.asDiagonal() * solver.solve(right);
  if (!step.allFinite()) return std::nullopt;
  return step;
}

}  // namespace elo
