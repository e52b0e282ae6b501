// The projection's per-point motion compensation (scanPointVertex() of scan_projection.hpp) for 8 points
// at once, with AVX. Point by point, each point's time is a switch on its source and, from the azimuth,
// a chain of divisions with branches; the exponential's coefficients branch on the angle. In lanes the
// azimuth times are found together (lanes::fastAtan2(), bit for bit the scalar one), and where every
// point of the group turns little (TwistCoefficients::kSmallSquaredAngle: all but the fastest turns)
// the coefficients are the short series', without a branch, and the points are moved in lanes too. Each
// lane performs the shared functions' float operations in their order (each point is still corrected by
// the shared function), so it gives what scanPointVertex() gives, bit for bit (test_deskew.cpp).
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

namespace lanes {

// cross(a, b) with a the same in every lane, in cross()'s order of operations.
inline void cross(const Float3& a, __m256 bx, __m256 by, __m256 bz, __m256& x, __m256& y, __m256& z) {
  const __m256 ax = _mm256_set1_ps(a.x), ay = _mm256_set1_ps(a.y), az = _mm256_set1_ps(a.z);
  x = _mm256_sub_ps(_mm256_mul_ps(ay, bz), _mm256_mul_ps(az, by));
  y = _mm256_sub_ps(_mm256_mul_ps(az, bx), _mm256_mul_ps(ax, bz));
  z = _mm256_sub_ps(_mm256_mul_ps(ax, by), _mm256_mul_ps(ay, bx));
}

// p + u * s + w * r, lane by lane, in rotateAt()'s order.
inline __m256 addScaled(__m256 p, __m256 u, __m256 s, __m256 w, __m256 r) {
  return _mm256_add_ps(_mm256_add_ps(p, _mm256_mul_ps(u, s)), _mm256_mul_ps(w, r));
}

// deskewPoint() of points measured at times `t` that all turn little: the short series' coefficients
// (TwistCoefficients::ofSmallSquaredAngle()), rotateAt() plus translationAt(), each in its order of
// operations. The points (x, y, z) become their vertices.
inline void deskewLittleTurns(const SweepVelocity& velocity, __m256 t, __m256& x, __m256& y, __m256& z) {
  const __m256 s = _mm256_mul_ps(_mm256_mul_ps(_mm256_set1_ps(velocity.angular_squared), t), t);
  const __m256 a = _mm256_add_ps(_mm256_set1_ps(1.0f), _mm256_mul_ps(s, _mm256_set1_ps(-1.0f / 6.0f)));
  const __m256 b = _mm256_add_ps(_mm256_set1_ps(0.5f), _mm256_mul_ps(s, _mm256_set1_ps(-1.0f / 24.0f)));
  const __m256 c = _mm256_add_ps(_mm256_set1_ps(1.0f / 6.0f), _mm256_mul_ps(s, _mm256_set1_ps(-1.0f / 120.0f)));
  // rotateAt(): p + once (a t) + cross(w, once) (b t t).
  __m256 once_x, once_y, once_z, twice_x, twice_y, twice_z;
  cross(velocity.angular, x, y, z, once_x, once_y, once_z);
  cross(velocity.angular, once_x, once_y, once_z, twice_x, twice_y, twice_z);
  const __m256 a_t = _mm256_mul_ps(a, t);
  const __m256 b_t_t = _mm256_mul_ps(_mm256_mul_ps(b, t), t);
  // translationAt(): v t + (w x v) (b t^2) + (w x (w x v)) (c t^2 t).
  const __m256 t_squared = _mm256_mul_ps(t, t);
  const __m256 b_t2 = _mm256_mul_ps(b, t_squared);
  const __m256 c_t2_t = _mm256_mul_ps(_mm256_mul_ps(c, t_squared), t);
  const auto translation = [&](float linear, float turned, float twice_turned) {
    return addScaled(_mm256_mul_ps(_mm256_set1_ps(linear), t), _mm256_set1_ps(turned), b_t2,
                     _mm256_set1_ps(twice_turned), c_t2_t);
  };
  x = _mm256_add_ps(addScaled(x, once_x, a_t, twice_x, b_t_t),
                    translation(velocity.linear.x, velocity.turned_linear.x, velocity.twice_turned_linear.x));
  y = _mm256_add_ps(addScaled(y, once_y, a_t, twice_y, b_t_t),
                    translation(velocity.linear.y, velocity.turned_linear.y, velocity.twice_turned_linear.y));
  z = _mm256_add_ps(addScaled(z, once_z, a_t, twice_z, b_t_t),
                    translation(velocity.linear.z, velocity.turned_linear.z, velocity.twice_turned_linear.z));
}

}  // namespace lanes

// A group's points as placed: the lanes with a point (finite, with a time of this sweep) and their
// vertices.
struct PlacedLanes {
  unsigned usable;
  __m256 x;
  __m256 y;
  __m256 z;
};

// The usable points of a group (`group.usable`) as measured, at their times, turned by the gyro's
// rotation and moved: deskewPoint() of a SweepRotation, point by point. The others keep their measured
// point (they are not offered).
inline void placeTurnedLanes(const SweepDeskew& deskew, const float (&measured)[3][kPixelLanes],
                             const float (&time)[kPixelLanes], size_t first, ScanPoint* placed, PlacedLanes& group) {
  float vertex[3][kPixelLanes];
  for (int lane = 0; lane < kPixelLanes; ++lane) {
    ScanPoint& point = placed[first + lane];
    point.measured = {measured[0][lane], measured[1][lane], measured[2][lane]};
    point.time = time[lane];
    point.vertex = (group.usable & (1u << lane)) ? deskewPoint(deskew.rotation, deskew.velocity, time[lane], point.measured)
                                                 : point.measured;
    vertex[0][lane] = point.vertex.x;
    vertex[1][lane] = point.vertex.y;
    vertex[2][lane] = point.vertex.z;
  }
  group.x = _mm256_loadu_ps(vertex[0]);
  group.y = _mm256_loadu_ps(vertex[1]);
  group.z = _mm256_loadu_ps(vertex[2]);
}

// scanPointVertex() of the points [first, first + kPixelLanes) of `xyz` (x, y, z after one another),
// each one's measured point, time and vertex into `placed`, bit for bit. False, with the group's vertices
// not computed, where a point that has a time turns by more than the short series' bound: the caller
// places that group point by point. A sweep a gyro's rotation turns (SweepRotation) has its times found
// in lanes and each point turned by the shared function.
inline bool placeLanes(const ElevationCorrection& correction, const SweepDeskew& deskew, const float* xyz,
                       size_t first, ScanPoint* placed, PlacedLanes& group) {
  __m256 raw_x, raw_y, raw_z;
  loadPointLanes(xyz + 3 * first, raw_x, raw_y, raw_z);
  const unsigned finite = finiteLanes(raw_x, raw_y, raw_z);
  float raw[3][kPixelLanes];
  _mm256_storeu_ps(raw[0], raw_x);
  _mm256_storeu_ps(raw[1], raw_y);
  _mm256_storeu_ps(raw[2], raw_z);
  float measured[3][kPixelLanes], time[kPixelLanes];
  for (int lane = 0; lane < kPixelLanes; ++lane) {
    const Float3 point = correction.apply({raw[0][lane], raw[1][lane], raw[2][lane]});
    measured[0][lane] = point.x;
    measured[1][lane] = point.y;
    measured[2][lane] = point.z;
  }
  __m256 x = _mm256_loadu_ps(measured[0]), y = _mm256_loadu_ps(measured[1]), z = _mm256_loadu_ps(measured[2]);
  const SweepTiming& timing = deskew.timing;
  unsigned timed = (1u << kPixelLanes) - 1;
  if (timing.source == TimeSource::azimuth) {
    _mm256_storeu_ps(time, azimuthTimes(timing, x, y));
  } else {
    for (int lane = 0; lane < kPixelLanes; ++lane) {
      const Float3 point{measured[0][lane], measured[1][lane], measured[2][lane]};
      if (!timing.pointTime(deskew.times, static_cast<int>(first) + lane, point, time[lane])) timed &= ~(1u << lane);
    }
  }
  group.usable = finite & timed;
  if (deskew.rotation.known) {
    placeTurnedLanes(deskew, measured, time, first, placed, group);
    return true;
  }
  const SweepVelocity& velocity = deskew.velocity;
  for (int lane = 0; lane < kPixelLanes; ++lane) {
    const bool turns_little = velocity.angular_squared * time[lane] * time[lane] < TwistCoefficients::kSmallSquaredAngle;
    if ((group.usable & (1u << lane)) && !turns_little) return false;
  }
  if (!velocity.isZero()) lanes::deskewLittleTurns(velocity, _mm256_loadu_ps(time), x, y, z);
  float vertex[3][kPixelLanes];
  _mm256_storeu_ps(vertex[0], x);
  _mm256_storeu_ps(vertex[1], y);
  _mm256_storeu_ps(vertex[2], z);
  for (int lane = 0; lane < kPixelLanes; ++lane) {
    ScanPoint& point = placed[first + lane];
    point.measured = {measured[0][lane], measured[1][lane], measured[2][lane]};
    point.vertex = {vertex[0][lane], vertex[1][lane], vertex[2][lane]};
    point.time = time[lane];
  }
  group.x = x;
  group.y = y;
  group.z = z;
  return true;
}

}  // namespace elo::cpu

#endif  // ELO_PIXEL_LANES
