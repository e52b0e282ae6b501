// Motion compensation per point, shared by both backends (docs/deskew.md). A spinning LiDAR measures each
// point in the sensor frame of its own firing instant; the scan's pose refers to one reference instant.
// Over one sweep the sensor moves at a constant twist (v, w) per second in the frame of the reference
// instant, so a point fired `t` seconds after it was measured in the frame exp(t (v, w)), and moves to
// the reference frame by that transform.
#pragma once

#include <cmath>

#include "elo/config.hpp"
#include "elo/device_types.hpp"
#include "elo/projections.hpp"  // fastAtan2

namespace elo {

// The sensor's velocity over a sweep: a twist per second in the frame of the reference instant.
struct SweepVelocity {
  Float3 linear;   // m/s
  Float3 angular;  // rad/s

  ELO_HOST_DEVICE bool isZero() const { return elo::isZero(linear) && elo::isZero(angular); }
};

// The coefficients of the SE(3) exponential of a twist whose rotation turns by `angle`:
// R = I + a [phi]x + b [phi]x^2 and V = I + b [phi]x + c [phi]x^2. Below half a radian (a sweep at up to
// 5 rad/s either side of the reference) the Taylor series to the 6th power is exact to float precision
// (the first term left out is under 1.1e-8) and, being plain arithmetic, rounds the same on both
// backends; above it the closed forms.
struct TwistCoefficients {
  float a;
  float b;
  float c;

  ELO_HOST_DEVICE static TwistCoefficients ofSquaredAngle(float angle_squared) {
    const float s = angle_squared;
    if (s < 0.25f) {
      return {1.0f - s / 6.0f * (1.0f - s / 20.0f * (1.0f - s / 42.0f)),
              0.5f - s / 24.0f * (1.0f - s / 30.0f * (1.0f - s / 56.0f)),
              1.0f / 6.0f - s / 120.0f * (1.0f - s / 42.0f * (1.0f - s / 72.0f))};
    }
    const float angle = std::sqrt(s);
    const float sine = std::sin(angle);
    return {sine / angle, (1.0f - std::cos(angle)) / s, (angle - sine) / (s * angle)};
  }
};

// R p = p + a (phi x p) + b (phi x (phi x p)).
ELO_HOST_DEVICE inline Float3 rotateByVector(const Float3& phi, const TwistCoefficients& k, const Float3& p) {
  const Float3 once = cross(phi, p);
  return p + once * k.a + cross(phi, once) * k.b;
}

// The point `p`, measured `time` seconds after the reference instant, in the reference frame.
ELO_HOST_DEVICE inline Float3 deskewPoint(const SweepVelocity& velocity, float time, const Float3& p) {
  const Float3 phi = velocity.angular * time;
  const Float3 rho = velocity.linear * time;
  const TwistCoefficients k = TwistCoefficients::ofSquaredAngle(squaredNorm(phi));
  const Float3 rho_once = cross(phi, rho);
  const Float3 translation = rho + rho_once * k.b + cross(phi, rho_once) * k.c;
  return rotateByVector(phi, k, p) + translation;
}

// A direction (a normal) at `time`, turned as deskewPoint() turns points.
ELO_HOST_DEVICE inline Float3 deskewDirection(const SweepVelocity& velocity, float time, const Float3& n) {
  const Float3 phi = velocity.angular * time;
  return rotateByVector(phi, TwistCoefficients::ofSquaredAngle(squaredNorm(phi)), n);
}

// Where each point's time comes from, and the sweep it belongs to.
struct SweepTiming {
  TimeSource source;
  float turn_sign;      // the azimuth's change over time: -1 for a clockwise sensor, +1 counter-clockwise
  float start_azimuth;  // rad, where the sweep starts
  float period;         // s, one revolution
  // A per-point time (field) farther than this from the reference is no time of this sweep: two
  // revolutions, so that drivers stamping a sweep at its start, middle or end all fit, and so does a
  // sensor turning at half the configured rate.
  float max_offset;

  static SweepTiming fromConfig(const SensorConfig& sensor, TimeSource source) {
    const float period = static_cast<float>(1.0 / sensor.rotation_rate_hz);
    return {source, sensor.clockwise ? -1.0f : 1.0f, static_cast<float>(sensor.sweep_start_azimuth_deg * M_PI / 180.0),
            period, 2.0f * period};
  }

  // A per-point time this sweep can have (false for NaN too).
  ELO_HOST_DEVICE bool withinSweep(float time) const { return std::fabs(time) <= max_offset; }

  // The time of a point from its azimuth, relative to mid-sweep: the azimuth's turn from the start, as a
  // fraction f of the revolution, gives (f - 0.5) * period. KITTI's HDL-64E (clockwise from straight
  // behind): f = 0.5 * (1 - atan2(y, x) / pi).
  ELO_HOST_DEVICE float azimuthTime(const Float3& p) const {
    const float turned = turn_sign * (fastAtan2(p.y, p.x) - start_azimuth) * static_cast<float>(0.5 * M_1_PI);
    return (turned - std::floor(turned) - 0.5f) * period;
  }

  // The time of cloud point `index` (`measured`, with `times` the cloud's per-point times, null when it
  // has none). False when its own time is not one of this sweep: the point is dropped.
  ELO_HOST_DEVICE bool pointTime(const float* times, int index, const Float3& measured, float& time) const {
    switch (source) {
      case TimeSource::field:
        time = times[index];
        return withinSweep(time);
      case TimeSource::azimuth:
        time = azimuthTime(measured);
        return true;
      default:
        time = 0.0f;
        return true;
    }
  }
};

// The deskew of one scan's projection: how its points are timed, the cloud's per-point times (null unless
// the source is `field`) and the velocity the points are moved under.
struct SweepDeskew {
  SweepTiming timing;
  const float* times;
  SweepVelocity velocity;

  // Cloud point `index`, as `measured`, moved to the reference instant; false when it has no usable time.
  ELO_HOST_DEVICE bool apply(int index, const Float3& measured, float& time, Float3& deskewed) const {
    if (!timing.pointTime(times, index, measured, time)) return false;
    deskewed = velocity.isZero() ? measured : deskewPoint(velocity, time, measured);
    return true;
  }
};

// A projected pixel deskewed again under `velocity` after it was under `applied`: the vertex from the
// point as measured, the normal turned back to the firing frame and forward again. Deskewing changes a
// normal's window as a whole (its points were fired within a fraction of a millisecond of each other), so
// turning the normal is what estimating it again would give.
ELO_HOST_DEVICE inline void redeskewPixel(const SweepVelocity& applied, const SweepVelocity& velocity,
                                          const Float3& measured, float time, Float3& vertex, float& range,
                                          Float3& normal) {
  vertex = deskewPoint(velocity, time, measured);
  range = norm(vertex);
  if (!isZero(normal)) normal = deskewDirection(velocity, time, deskewDirection(applied, -time, normal));
}

}  // namespace elo
