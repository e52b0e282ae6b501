// Host conversions between Eigen and the Eigen-free types of the shared per-element math. Both backends
// convert a pose the same way, so their kernels apply the same float transform.
#pragma once

#include <Eigen/Geometry>

#include "elo/device_types.hpp"

namespace elo {

inline Float3 toFloat3(const Eigen::Vector3f& v) { return {v.x(), v.y(), v.z()}; }
inline Eigen::Vector3f toVec3f(const Float3& v) { return {v.x, v.y, v.z}; }

inline Rigid3f toRigid3f(const Eigen::Isometry3d& transform) {
  Rigid3f rigid;
  for (int row = 0; row < 3; ++row) {
    for (int col = 0; col < 3; ++col) rigid.r[3 * row + col] = static_cast<float>(transform.linear()(row, col));
  }
  rigid.t = {static_cast<float>(transform.translation().x()), static_cast<float>(transform.translation().y()),
             static_cast<float>(transform.translation().z())};
  return rigid;
}

}  // namespace elo
