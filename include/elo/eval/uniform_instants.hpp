// Ground truth at the scans' own instants. KITTI-raw pairs each scan with the OXTS sample (100 Hz) nearest
// its trigger, so `times.txt` and the poses step by 0.10 or 0.11 s while the sensor, turning at a steady
// rate, takes a scan every 0.1035 s: each ground-truth pose is up to 5 ms (0.1 m at 20 m/s) from the
// scan's instant (docs/real_drives.md). The scans' instants are the line fitted to the stamps, and the
// ground truth is interpolated to them.
#pragma once

#include <Eigen/Geometry>
#include <vector>

namespace elo {

struct UniformInstants {
  std::vector<double> instants;  // one a stamp, on the fitted line
  double period_s = 0.0;
  double largest_offset_s = 0.0;  // the largest |stamp - instant|
};

// The least-squares line through (i, stamps[i]). Throws std::invalid_argument for fewer than two stamps,
// stamps that do not increase, or a stamp more than half a period off the line: a sensor that did not
// turn at a steady rate (a gap, a restart), whose scans the line does not describe.
UniformInstants fitUniformInstants(const std::vector<double>& stamps);

// The poses, sampled at `stamps`, interpolated (positions linearly, rotations along the geodesic) at
// `instants`; an instant beyond the first or last stamp is extrapolated from the nearest two. Throws
// std::invalid_argument when the poses and stamps differ in number or fewer than two are given.
std::vector<Eigen::Isometry3d> interpolatePoses(const std::vector<Eigen::Isometry3d>& poses,
                                                const std::vector<double>& stamps,
                                                const std::vector<double>& instants);

}  // namespace elo
