// Motion compensation per point, shared by both backends (docs/deskew.md). A spinning LiDAR measures each
// point in the sensor frame of its own firing instant; the scan's pose refers to one reference instant.
// Over one sweep the sensor moves at a constant twist (v, w) per second in the frame of the reference
// instant, so a point fired `t` seconds after it was measured in the frame exp(t (v, w)), and moves to
// the reference frame by that transform.
#pragma once

#include <cmath>

#include "elo/config.hpp"
#include "elo/device_types.hpp"
#include "elo/sensor/projections.hpp"  // fastAtan2

namespace elo {

// The sensor's velocity over a sweep: a twist (v, w) per second in the frame of the reference instant,
// with the products of the exponential that do not depend on time, formed once per scan (of()).
struct SweepVelocity {
  Float3 linear;   // v, m/s
  Float3 angular;  // w, rad/s
  float angular_squared;  // |w|^2
  Float3 turned_linear;   // w x v
  Float3 twice_turned_linear;  // w x (w x v)

  ELO_HOST_DEVICE static SweepVelocity of(const Float3& linear, const Float3& angular) {
    const Float3 turned = cross(angular, linear);
    return {linear, angular, squaredNorm(angular), turned, cross(angular, turned)};
  }
  ELO_HOST_DEVICE bool isZero() const { return elo::isZero(linear) && elo::isZero(angular); }
};

// The coefficients of the SE(3) exponential of a twist whose rotation turns by theta:
// R = I + a [phi]x + b [phi]x^2 and V = I + b [phi]x + c [phi]x^2, phi the rotation vector. Below half a
// radian (a sweep at up to 5 rad/s either side of the reference) the Taylor series to theta^6 is exact
// to float precision (the first term left out is under 1.1e-8) and, being plain arithmetic, rounds the
// same on both backends; above it the closed forms. Below 0.03 rad (a car turning at up to 0.6 rad/s,
// half a sweep from the reference: nearly every point) the series to theta^2 is exact to float precision
// already (the first term left out under 8.3e-9), at a third of the arithmetic.
struct TwistCoefficients {
  float a;
  float b;
  float c;

  // Below this squared angle the series to theta^2 (ofSmallSquaredAngle()) is exact to float precision.
  static constexpr float kSmallSquaredAngle = 1e-3f;

  ELO_HOST_DEVICE static TwistCoefficients ofSquaredAngle(float angle_squared) {
    const float s = angle_squared;
    if (s < kSmallSquaredAngle) return ofSmallSquaredAngle(s);
    if (s < 0.25f) {
      return {1.0f + s * (-1.0f / 6.0f + s * (1.0f / 120.0f + s * (-1.0f / 5040.0f))),
              0.5f + s * (-1.0f / 24.0f + s * (1.0f / 720.0f + s * (-1.0f / 40320.0f))),
              1.0f / 6.0f + s * (-1.0f / 120.0f + s * (1.0f / 5040.0f + s * (-1.0f / 362880.0f)))};
    }
    const float angle = std::sqrt(s);
    const float sine = std::sin(angle);
    return {sine / angle, (1.0f - std::cos(angle)) / s, (angle - sine) / (s * angle)};
  }
  // ofSquaredAngle() below kSmallSquaredAngle: branch-free, so that a loop over pixels all below it
  // vectorises.
  ELO_HOST_DEVICE static TwistCoefficients ofSmallSquaredAngle(float s) {
    return {1.0f + s * (-1.0f / 6.0f), 0.5f + s * (-1.0f / 24.0f), 1.0f / 6.0f + s * (-1.0f / 120.0f)};
  }
};

// The rotation of exp(time (v, w)) applied to `p`: p + a t (w x p) + b t^2 (w x (w x p)), phi = t w.
ELO_HOST_DEVICE inline Float3 rotateAt(const SweepVelocity& velocity, float time, const TwistCoefficients& k,
                                       const Float3& p) {
  const Float3 once = cross(velocity.angular, p);
  return p + once * (k.a * time) + cross(velocity.angular, once) * (k.b * time * time);
}

// The translation of exp(time (v, w)): V t v = t v + b t^2 (w x v) + c t^3 (w x (w x v)).
ELO_HOST_DEVICE inline Float3 translationAt(const SweepVelocity& velocity, float time, const TwistCoefficients& k) {
  const float time_squared = time * time;
  return velocity.linear * time + velocity.turned_linear * (k.b * time_squared) +
         velocity.twice_turned_linear * (k.c * time_squared * time);
}

ELO_HOST_DEVICE inline TwistCoefficients coefficientsAt(const SweepVelocity& velocity, float time) {
  return TwistCoefficients::ofSquaredAngle(velocity.angular_squared * time * time);
}

// The point `p`, measured `time` seconds after the reference instant, in the reference frame:
// exp(time (v, w)) p.
ELO_HOST_DEVICE inline Float3 deskewPoint(const SweepVelocity& velocity, float time, const Float3& p) {
  const TwistCoefficients k = coefficientsAt(velocity, time);
  return rotateAt(velocity, time, k, p) + translationAt(velocity, time, k);
}

// A direction (a normal) at `time`, turned as deskewPoint() turns points.
ELO_HOST_DEVICE inline Float3 deskewDirection(const SweepVelocity& velocity, float time, const Float3& n) {
  return rotateAt(velocity, time, coefficientsAt(velocity, time), n);
}

// The sensor's rotation over a sweep by the gyro (GyroSweep, include/elo/imu/gyro_sweep.hpp), in float for
// the kernels: each point turned by the rotation at its own time, where a SweepVelocity turns it at one
// constant rate. kIntervals intervals of `step` seconds from `first` (s from the reference instant); over
// interval k, `within` seconds after its start, the frame is rotation_k exp(turn), turn = mean_rate_k within
// + rate_change_k within (within - step): rotation_{k+1} at its end, the rate linear in time between the
// gyro's rates at the two knots (exact for a rate linear in time about a fixed axis). Before the first and
// after the last knot, the end interval's mean rate. Passed by value to the projection's kernels (in
// SweepDeskew): 1,040 bytes.
struct SweepRotation {
  static constexpr int kIntervals = 16;

  struct Interval {
    float start;        // s from the reference instant
    float rotation[9];  // the frame at `start` in the reference frame, row-major
    Float3 mean_rate;   // rad/s: log(rotation_k^T rotation_{k+1}) / step
    Float3 rate_change;  // rad/s^2: (rate_{k+1} - rate_k) / (2 step)
  };

  int known;  // 0: no gyro; the sweep turns at the velocity's rate
  float first;
  float step;
  float intervals_per_second;
  Interval interval[kIntervals];

  // The interval a point `time` seconds from the reference falls in; the end ones beyond the knots.
  ELO_HOST_DEVICE int intervalOf(float time) const {
    const float position = (time - first) * intervals_per_second;
    if (!(position >= 1.0f)) return 0;
    if (position >= static_cast<float>(kIntervals - 1)) return kIntervals - 1;
    return static_cast<int>(position);
  }

  // `p`, measured `time` seconds from the reference instant, turned into the reference frame.
  ELO_HOST_DEVICE Float3 rotate(float time, const Float3& p) const {
    const Interval& at = interval[intervalOf(time)];
    const float within = time - at.start;
    const float bent = within < 0.0f ? 0.0f : (within > step ? step : within);  // a constant rate beyond the knots
    const Float3 turn = at.mean_rate * within + at.rate_change * (bent * (bent - step));
    const TwistCoefficients k = TwistCoefficients::ofSquaredAngle(squaredNorm(turn));
    const Float3 once = cross(turn, p);
    const Float3 turned = p + once * k.a + cross(turn, once) * k.b;
    const float* r = at.rotation;
    return {r[0] * turned.x + r[1] * turned.y + r[2] * turned.z, r[3] * turned.x + r[4] * turned.y + r[5] * turned.z,
            r[6] * turned.x + r[7] * turned.y + r[8] * turned.z};
  }
};

// The translation of exp(time (v, w)) under a gyro's rotation: its series to the third order, v t +
// (w x v) t^2 / 2 + (w x (w x v)) t^3 / 6, without translationAt()'s corrections of the coefficients (the
// largest, at 3 rad/s half a sweep from the reference, a few micrometres; the translation's own turn at
// the gyro's mean rate w, not at its rotation, is a sub-millimetre approximation already). Branch-free,
// so that the CPU's loops over points and pixels vectorise.
ELO_HOST_DEVICE inline Float3 gyroTranslationAt(const SweepVelocity& velocity, float time) {
  const float time_squared = time * time;
  return velocity.linear * time + velocity.turned_linear * (0.5f * time_squared) +
         velocity.twice_turned_linear * ((1.0f / 6.0f) * time_squared * time);
}

// The point `p`, measured `time` seconds after the reference instant, in the reference frame, turned by
// the gyro's rotation at its time and moved by the velocity's translation (gyroTranslationAt()).
ELO_HOST_DEVICE inline Float3 deskewPoint(const SweepRotation& rotation, const SweepVelocity& velocity, float time,
                                          const Float3& p) {
  return rotation.rotate(time, p) + gyroTranslationAt(velocity, time);
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
  // The instant the points are moved to, in the cloud's per-point times (field; s): the scan's mid-sweep
  // (CloudTimes::reference). A point's time is taken relative to it.
  float reference;

  static SweepTiming fromConfig(const SensorConfig& sensor, TimeSource source, float reference = 0.0f) {
    const float period = static_cast<float>(1.0 / sensor.rotation_rate_hz);
    return {source, sensor.clockwise ? -1.0f : 1.0f, static_cast<float>(sensor.sweep_start_azimuth_deg * M_PI / 180.0),
            period, 2.0f * period, reference};
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
  // has none), relative to the reference. False when its own time is not one of this sweep: the point is
  // dropped.
  ELO_HOST_DEVICE bool pointTime(const float* times, int index, const Float3& measured, float& time) const {
    switch (source) {
      case TimeSource::field:
        time = times[index] - reference;
        return withinSweep(times[index]);
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
// the source is `field`), the velocity the points are moved under and, with a gyro, the rotation that
// turns them instead of the velocity's rate.
struct SweepDeskew {
  SweepTiming timing;
  const float* times;
  SweepVelocity velocity;
  SweepRotation rotation = {};

  // Cloud point `index`, as `measured`, moved to the reference instant; false when it has no usable time.
  ELO_HOST_DEVICE bool apply(int index, const Float3& measured, float& time, Float3& deskewed) const {
    if (!timing.pointTime(times, index, measured, time)) return false;
    if (rotation.known) {
      deskewed = deskewPoint(rotation, velocity, time, measured);
    } else {
      deskewed = velocity.isZero() ? measured : deskewPoint(velocity, time, measured);
    }
    return true;
  }
};

// A projected pixel deskewed again under `velocity` after it was under `applied`: the vertex from the
// point as measured, the normal turned back to the firing frame and forward again. Deskewing changes a
// normal's window as a whole (its points were fired within a fraction of a millisecond of each other), so
// turning the normal is what estimating it again would give.
// `forward` and `back` are the exponential's coefficients of `velocity` at `time` and of `applied` at
// -time (coefficientsAt()).
ELO_HOST_DEVICE inline void redeskewPixelWith(const SweepVelocity& applied, const SweepVelocity& velocity,
                                              const TwistCoefficients& forward, const TwistCoefficients& back,
                                              const Float3& measured, float time, Float3& vertex, float& range,
                                              Float3& normal) {
  vertex = rotateAt(velocity, time, forward, measured) + translationAt(velocity, time, forward);
  range = norm(vertex);
  // Computed for every pixel and then chosen, so that the CPU's loop over pixels has no branch.
  const Float3 turned = rotateAt(velocity, time, forward, rotateAt(applied, -time, back, normal));
  normal = choose(isZero(normal), normal, turned);
}

ELO_HOST_DEVICE inline void redeskewPixel(const SweepVelocity& applied, const SweepVelocity& velocity,
                                          const Float3& measured, float time, Float3& vertex, float& range,
                                          Float3& normal) {
  redeskewPixelWith(applied, velocity, coefficientsAt(velocity, time), coefficientsAt(applied, -time), measured,
                    time, vertex, range, normal);
}

// A projected pixel, turned by a gyro's rotation (deskewPoint() of a SweepRotation), deskewed again under
// `velocity` after `applied`: the rotation stays, so its vertex moves by the change of the translation at
// its time (computed for every pixel, so that the CPU's loop vectorises), and its normal stays as it is.
ELO_HOST_DEVICE inline Float3 turnedPixelMoved(const SweepVelocity& applied, const SweepVelocity& velocity,
                                               float time, const Float3& vertex) {
  return vertex + (gyroTranslationAt(velocity, time) - gyroTranslationAt(applied, time));
}

}  // namespace elo
