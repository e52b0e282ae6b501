// The projection's per-point motion compensation (scanPointVertex() of scan_projection.hpp) for 8 points
// at once, with AVX. Point by point, each point's time is a switch on its source and, from the azimuth,
// a chain of divisions with branches; the exponential's coefficients branch on the angle. In lanes the
// azimuth times are found together (lanes::fastAtan2(), bit for bit the scalar one), and where every
// point of the group turns little (TwistCoefficients::kSmallSquaredAngle: all but the fastest turns)
// the coefficients are the short series', without a branch. Each point is still corrected and moved by
// the shared functions, so each lane gives what scanPointVertex() gives, bit for bit (test_deskew.cpp).
#pragma once

#include "core/common/scan_projection.hpp"
#include "core/cpu/pixel_lanes.hpp"

#ifdef ELO_PIXEL_LANES

namespace elo::cpu {

// SweepTiming::azimuthTime() of the points (x[k], y[k]), in its order of operations.
inline __m256 azimuthTimes(const SweepTiming& timing, __m256 x, __m256 y) {
  const __m256 turned = _mm256_mul_ps(
      _mm256_mul_ps(_mm256_set1_ps(timing.turn_sign), _mm256_sub_ps(lanes::fastAtan2(y, x), _mm256_set1_ps(timing.start_azimuth))),
      _mm256_set1_ps(static_cast<float>(0.5 * M_1_PI)));
  const __m256 fraction = _mm256_sub_ps(_mm256_sub_ps(turned, _mm256_floor_ps(turned)), _mm256_set1_ps(0.5f));
  return _mm256_mul_ps(fraction, _mm256_set1_ps(timing.period));
}

// A group's points as placed: the lanes with a point (finite, with a time of this sweep) and their
// vertices.
struct PlacedLanes {
  unsigned usable;
  __m256 x;
  __m256 y;
  __m256 z;
};

// scanPointVertex() of the points [first, first + kPixelLanes) of `xyz` (x, y, z after one another),
// each one's measured point, time and vertex into `placed`, bit for bit. False, with the group's vertices
// not computed, where a point that has a time turns by more than the short series' bound: the caller
// places that group point by point.
inline bool placeLanes(const ElevationCorrection& correction, const SweepDeskew& deskew, const float* xyz,
                       size_t first, ScanPoint* placed, PlacedLanes& lanes) {
  __m256 raw_x, raw_y, raw_z;
  loadPointLanes(xyz + 3 * first, raw_x, raw_y, raw_z);
  const unsigned finite = finiteLanes(raw_x, raw_y, raw_z);
  float raw[3][kPixelLanes];
  _mm256_storeu_ps(raw[0], raw_x);
  _mm256_storeu_ps(raw[1], raw_y);
  _mm256_storeu_ps(raw[2], raw_z);
  float x[kPixelLanes], y[kPixelLanes], time[kPixelLanes];
  Float3 measured[kPixelLanes];
  for (int lane = 0; lane < kPixelLanes; ++lane) {
    measured[lane] = correction.apply({raw[0][lane], raw[1][lane], raw[2][lane]});
    x[lane] = measured[lane].x;
    y[lane] = measured[lane].y;
  }
  const SweepTiming& timing = deskew.timing;
  unsigned timed = (1u << kPixelLanes) - 1;
  if (timing.source == TimeSource::azimuth) {
    _mm256_storeu_ps(time, azimuthTimes(timing, _mm256_loadu_ps(x), _mm256_loadu_ps(y)));
  } else {
    for (int lane = 0; lane < kPixelLanes; ++lane) {
      if (!timing.pointTime(deskew.times, static_cast<int>(first) + lane, measured[lane], time[lane])) {
        timed &= ~(1u << lane);
      }
    }
  }
  lanes.usable = finite & timed;
  const SweepVelocity& velocity = deskew.velocity;
  for (int lane = 0; lane < kPixelLanes; ++lane) {
    const bool turns_little = velocity.angular_squared * time[lane] * time[lane] < TwistCoefficients::kSmallSquaredAngle;
    if ((lanes.usable & (1u << lane)) && !turns_little) return false;
  }
  const bool still = velocity.isZero();
  float vertex[3][kPixelLanes];
  for (int lane = 0; lane < kPixelLanes; ++lane) {
    ScanPoint& point = placed[first + lane];
    const float t = time[lane];
    const TwistCoefficients k = TwistCoefficients::ofSmallSquaredAngle(velocity.angular_squared * t * t);
    point.measured = measured[lane];
    point.time = t;
    point.vertex = still ? measured[lane] : rotateAt(velocity, t, k, measured[lane]) + translationAt(velocity, t, k);
    vertex[0][lane] = point.vertex.x;
    vertex[1][lane] = point.vertex.y;
    vertex[2][lane] = point.vertex.z;
  }
  lanes.x = _mm256_loadu_ps(vertex[0]);
  lanes.y = _mm256_loadu_ps(vertex[1]);
  lanes.z = _mm256_loadu_ps(vertex[2]);
  return true;
}

}  // namespace elo::cpu

#endif  // ELO_PIXEL_LANES
