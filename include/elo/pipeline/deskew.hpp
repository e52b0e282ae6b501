// Motion compensation on the host side (docs/deskew.md): which times a cloud's points get, and the
// velocity a scan is deskewed under. The per-point math is src/core/common/deskew.hpp.
#pragma once

#include <Eigen/Geometry>
#include <string>

#include "elo/config.hpp"
#include "elo/se3.hpp"
#include "elo/types.hpp"

namespace elo {

// The times a cloud's points get, from deskew.time_source and what the cloud carries.
struct CloudTimes {
  TimeSource source = TimeSource::none;  // none: the scan is taken as instantaneous
  // Why the cloud's own times (`field`) were not used, or not all used; empty when they were.
  std::string warning;
  size_t outside_sweep = 0;  // points whose time lies outside the sweep: the projection drops them
  // The reference instant the scan is deskewed to and registered at, in the cloud's per-point times (s):
  // the middle of the sweep, half-way between the earliest and the latest time the projection keeps
  // (`field`). Azimuth times count from mid-sweep already (0). A reference at one end of the sweep would
  // double the lever arm of any error in the velocity the scan is deskewed under and bend the scan all
  // one way, biasing its pose; at mid-sweep the errors of the two halves cancel (docs/deskew.md).
  double reference = 0.0;
  // The largest |time - reference| of a point the projection keeps (s): half the sweep; 0 for none.
  double farthest = 0.0;
};

// `field` needs one finite time per point, most of them within the sweep (SweepTiming::withinSweep()),
// and not all the same: a cloud without times, with as many as it has points, with its times mostly out
// of the sweep (a wrong unit or clock) or all equal (a driver that leaves them 0) is taken as
// instantaneous; a few points out of it (NaN, jumps) are dropped. Each case says so in `warning`.
CloudTimes inspectTimes(const PointCloud& cloud, const Config& config);

// The constant velocity, a twist per second, that moves the sensor by `increment` (T^{t-1}_t) in `dt`
// seconds: what a sweep around the scan's reference instant is deskewed under. Zero when dt is not
// positive.
Vector6d sweepVelocity(const Eigen::Isometry3d& increment, double dt);

// The time between two scans `stamp_interval` seconds apart by their stamps, as the motion between them
// is measured over: for `azimuth` times, a whole number of sweep periods (1 / sensor.rotation_rate_hz,
// at least one), since a spinning sensor's sweeps follow one another one period apart whatever their
// stamps say; the stamps' interval for the other sources. KITTI-raw's stamps come rounded to 10 ms (0.10
// and 0.11 s between scans): deskewed under the motion over those, every sweep was deskewed 5-10 % wrong,
// alternately, and the heading drift on drive 0027 was 0.59 deg/100 m instead of 0.33 (docs/real_drives.md).
double motionInterval(double stamp_interval, TimeSource source, const SensorConfig& sensor);

// Whether deskewing a sweep whose points lie up to `farthest` seconds from the reference under velocity
// `to` instead of `from` changes its registration: when it moves the sensor's pose at the sweep's ends
// by more than a converged registration step (registration.converged_translation and _rotation). Below
// that, registering again would stop at its first step.
bool changesRegistration(const Vector6d& from, const Vector6d& to, double farthest, const RegistrationConfig& config);

}  // namespace elo
