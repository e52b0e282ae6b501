// The LiDAR's rotation over one sweep by the gyro (docs/imu.md, docs/deskew.md): what turns each point of
// a sweep by the rotation at its own firing instant, where a constant twist would turn it at one rate.
#pragma once

#include <Eigen/Geometry>
#include <vector>

namespace elo {

// At kIntervals + 1 knots evenly spread over [first, last] (s from the scan's reference instant), the
// LiDAR's frame there in its frame at the reference instant, and its turn rate there (rad/s, the LiDAR's
// axes, the gyro's bias removed). Between two knots the rate is taken linear in time (SweepRotation of
// src/core/common/deskew.hpp); before the first and after the last, constant. 16 intervals: at 10 Hz a
// knot every 6 ms, about the spacing of a 200 Hz IMU's samples.
struct GyroSweep {
  static constexpr int kIntervals = 16;

  double first = 0.0;
  double last = 0.0;
  std::vector<Eigen::Matrix3d> rotations;  // kIntervals + 1; none: not known
  std::vector<Eigen::Vector3d> rates;      // kIntervals + 1

  bool known() const { return !rotations.empty(); }
};

}  // namespace elo
