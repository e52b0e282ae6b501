// Whether a cloud fits the configured sensor model (sensor.*): the share of its points the spherical
// projection cannot place because they lie above or below the range image's field of view or carry a
// ring index past the configured beams, and of those it places in the wrong row because their ring's
// beam (ringElevations()) is not where they are. Run with another LiDAR's settings (the HDL-64E
// defaults on a VLP-16's scans, say), a third of each scan falls off the image and the odometry drifts
// by metres with no other sign; with the other ring numbering (sensor.ring_zero: velodyne_pointcloud
// counts rings up from the lowest beam, ouster_ros down from the highest) every row is upside down.
// This check names the cause.
#pragma once

#include <cstddef>
#include <string>

#include "elo/config.hpp"
#include "elo/types.hpp"

namespace elo {

struct SensorFit {
  size_t sampled = 0;       // points looked at: finite, within the sensor's range
  size_t above = 0;         // of those, above sensor.fov_up_deg
  size_t below = 0;         // below sensor.fov_down_deg
  size_t unknown_ring = 0;  // with a ring index past the configured beams
  size_t off_beam = 0;      // at least kRingCheckRange away, and over kMaxBeamOffset from their ring's beam

  size_t misplaced() const { return above + below + unknown_ring + off_beam; }
  // Empty when at most kMaxMisplacedShare of the sampled points are misplaced; otherwise what is wrong,
  // in numbers, and where to look.
  std::string warning(const SensorConfig& sensor) const;
};

// More than this share of a scan off the sensor model is not noise: the settings are another sensor's.
constexpr double kMaxMisplacedShare = 0.05;
// A point's elevation seen from the sensor's origin differs from its beam's by the beam's calibration
// (tenths of a degree) and, close in, by where on the head the laser sits (0.2 m apart on an HDL-64E:
// under 0.8 deg beyond 15 m); beams are 0.3 to 2 deg apart, so the other ring numbering misses by more.
constexpr double kRingCheckRange = 15.0;  // m
constexpr double kMaxBeamOffsetDeg = 1.5;

// Every `stride`-th point of `cloud` against `sensor`'s field of view and beams (after the elevation
// correction, as the projection places them).
SensorFit checkSensorFit(const PointCloud& cloud, const SensorConfig& sensor, size_t stride);

// How far out a point still gets a normal (m), from the configuration alone. Test 1 of the normal's
// outlier tests (Sec. III-B.4, normals.method range_adaptive) refuses a point when most of its window
// lies farther than sigma_r (normals.outlier_distance), and the window spans at least three rows: the
// beams above and below, range x tan(gap) away. With the paper's 0.5 m and beams 2 deg apart (a VLP-16)
// no point beyond 14 m has a normal, and the heading slips where the near scene is bare
// (docs/accuracy.md). The gap is the median between adjacent beams. Infinite for the other methods.
double normalReach(const Config& config);

// Empty when normalReach() is at least kMinNormalReach (or the sensor's max_range, if shorter); otherwise
// the reach, the beams' gap and the normals.outlier_distance that reaches kMinNormalReach.
std::string normalReachWarning(const Config& config);
constexpr double kMinNormalReach = 25.0;  // m

}  // namespace elo
