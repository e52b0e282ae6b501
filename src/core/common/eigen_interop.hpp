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

// The gyro's rotation over a sweep in float; not known when `sweep` is not.
inline SweepRotation toSweepRotation(const GyroSweep& sweep) {
  static_assert(SweepRotation::kIntervals == GyroSweep::kIntervals, "one knot table on the host and the device");
  SweepRotation rotation{};
  if (!sweep.known()) return rotation;
  const double step = (sweep.last - sweep.first) / SweepRotation::kIntervals;
  rotation.known = 1;
  rotation.first = static_cast<float>(sweep.first);
  rotation.step = static_cast<float>(step);
  rotation.intervals_per_second = static_cast<float>(1.0 / step);
  for (int k = 0; k < SweepRotation::kIntervals; ++k) {
    SweepRotation::Interval& interval = rotation.interval[k];
    interval.start = static_cast<float>(sweep.first + k * step);
    const Eigen::Matrix3f rotation = sweep.rotations[k].cast<float>();
    for (int row = 0; row < 3; ++row) {
      for (int col = 0; col < 3; ++col) interval.rotation[3 * row + col] = rotation(row, col);
    }
    const Eigen::Vector3d mean_rate = logSO3(sweep.rotations[k].transpose() * sweep.rotations[k + 1]) / step;
    const Eigen::Vector3d rate_change = (sweep.rates[k + 1] - sweep.rates[k]) / (2.0 * step);
    interval.mean_rate = toFloat3(mean_rate.cast<float>().eval());
    interval.rate_change = toFloat3(rate_change.cast<float>().eval());
  }
  return rotation;
}

// The deskew of `cloud`'s projection under `motion` (Backend::projectScan()): per-point times from the
// cloud only when it has one for every point, else none.
inline SweepDeskew sweepDeskew(const SensorConfig& sensor, const PointCloud& cloud, const SweepMotion& motion) {
  const bool has_times = cloud.time.size() == cloud.points.size();
  const TimeSource source = motion.times == TimeSource::field && !has_times ? TimeSource::none : motion.times;
  return {SweepTiming::fromConfig(sensor, source, static_cast<float>(motion.reference)),
          source == TimeSource::field ? cloud.time.data() : nullptr,
          toSweepVelocity(source == TimeSource::none ? Vector6d::Zero() : motion.velocity),
          source == TimeSource::none ? SweepRotation{} : toSweepRotation(motion.gyro)};
}

}  // namespace elo
