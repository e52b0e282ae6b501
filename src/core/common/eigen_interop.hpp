// Host conversions between Eigen and the Eigen-free types of the shared per-element math. Both backends
// convert a pose the same way, so their kernels apply the same float transform.
#pragma once

#include <Eigen/Geometry>

#include "core/common/deskew.hpp"
#include "elo/pipeline/backend.hpp"  // SweepMotion
#include "elo/device_types.hpp"
#include "elo/types.hpp"

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

inline SweepVelocity toSweepVelocity(const Vector6d& twist) {
  return SweepVelocity::of({static_cast<float>(twist(0)), static_cast<float>(twist(1)), static_cast<float>(twist(2))},
                           {static_cast<float>(twist(3)), static_cast<float>(twist(4)), static_cast<float>(twist(5))});
}

// The deskew of `cloud`'s projection under `motion` (Backend::projectScan()): per-point times from the
// cloud only when it has one for every point, else none.
inline SweepDeskew sweepDeskew(const SensorConfig& sensor, const PointCloud& cloud, const SweepMotion& motion) {
  const bool has_times = cloud.time.size() == cloud.points.size();
  const TimeSource source = motion.times == TimeSource::field && !has_times ? TimeSource::none : motion.times;
  return {SweepTiming::fromConfig(sensor, source, static_cast<float>(motion.reference)),
          source == TimeSource::field ? cloud.time.data() : nullptr,
          toSweepVelocity(source == TimeSource::none ? Vector6d::Zero() : motion.velocity)};
}

}  // namespace elo
