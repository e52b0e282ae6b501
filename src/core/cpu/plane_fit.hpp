// Least-squares plane of a few points by eigen-decomposition of their covariance (Eq. 10-11).
#pragma once

#include <Eigen/Eigenvalues>

#include "elo/types.hpp"

namespace elo::cpu {

struct PlaneFit {
  Vec3f normal = Vec3f::Zero();  // eigenvector of the smallest eigenvalue
  float curvature = 1.0f;        // lambda3 / (lambda1 + lambda2 + lambda3)
  bool valid = false;
};

// The first and second moments of a set of points, accumulated one point at a time. Points are given
// relative to a nearby origin (the centre of a normal window), so float sums keep their precision.
struct PointMoments {
  Eigen::Vector3f sum = Eigen::Vector3f::Zero();
  Eigen::Matrix3f outer = Eigen::Matrix3f::Zero();  // sum of p p^T
  int count = 0;

  void add(const Vec3f& p) {
    sum += p;
    outer.noalias() += p * p.transpose();
    ++count;
  }

  // The covariance of the points about their mean.
  Eigen::Matrix3f covariance() const {
    const Eigen::Vector3f mean = sum / static_cast<float>(count);
    return outer / static_cast<float>(count) - mean * mean.transpose();
  }
};

// The plane of the points whose moments are given: eigen-decomposition of their covariance (Eq. 10-11).
inline PlaneFit fitPlane(const PointMoments& moments) {
  PlaneFit fit;
  if (moments.count < 3) return fit;
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix3f> solver;
  solver.computeDirect(moments.covariance());
  const Eigen::Vector3f eigenvalues = solver.eigenvalues();  // ascending
  const float sum = eigenvalues.sum();
  if (!(sum > 0.0f)) return fit;
  fit.normal = solver.eigenvectors().col(0).normalized();
  fit.curvature = std::max(eigenvalues(0), 0.0f) / sum;
  fit.valid = fit.normal.allFinite();
  return fit;
}

}  // namespace elo::cpu
