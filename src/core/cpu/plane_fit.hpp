// Least-squares plane of a few points by eigen-decomposition of their covariance (Eq. 10-11).
#pragma once

#include <Eigen/Eigenvalues>

#include "elo/types.hpp"

namespace elo::cpu {

struct PlaneFit {
  Vec3f normal = Vec3f::Zero();  // eigenvector of the smallest eigenvalue
  float curvature = 1.0f;        // lambda3 / (lambda1 + lambda2 + lambda3)
  double middle_eigenvalue = 0.0;  // lambda2: near zero when the points lie on a line
  bool valid = false;
};

// `points[0..count)` are taken relative to `origin` so that float coordinates far from the sensor keep
// their precision in the double covariance.
inline PlaneFit fitPlane(const Vec3f* points, int count, const Vec3f& origin) {
  PlaneFit fit;
  if (count < 3) return fit;
  Eigen::Vector3d mean = Eigen::Vector3d::Zero();
  for (int i = 0; i < count; ++i) mean += (points[i] - origin).cast<double>();
  mean /= count;
  Eigen::Matrix3d covariance = Eigen::Matrix3d::Zero();
  for (int i = 0; i < count; ++i) {
    const Eigen::Vector3d d = (points[i] - origin).cast<double>() - mean;
    covariance.noalias() += d * d.transpose();
  }
  covariance /= count;
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> solver;
  solver.computeDirect(covariance);
  const Eigen::Vector3d eigenvalues = solver.eigenvalues();  // ascending
  const double sum = eigenvalues.sum();
  if (!(sum > 0.0)) return fit;
  fit.normal = solver.eigenvectors().col(0).cast<float>().normalized();
  fit.curvature = static_cast<float>(std::max(eigenvalues(0), 0.0) / sum);
  fit.middle_eigenvalue = eigenvalues(1);
  fit.valid = fit.normal.allFinite();
  return fit;
}

}  // namespace elo::cpu
