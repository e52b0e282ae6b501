#include "elo/pipeline/deskew.hpp"

#include <algorithm>
#include <cmath>

#include "core/common/deskew.hpp"

namespace elo {

CloudTimes inspectTimes(const PointCloud& cloud, const Config& config) {
  CloudTimes times;
  times.source = config.deskew.time_source;
  if (times.source == TimeSource::azimuth) times.farthest = 0.5 / config.sensor.rotation_rate_hz;
  if (times.source != TimeSource::field) return times;
  times.source = TimeSource::none;
  if (cloud.time.empty()) {
    times.warning = "no per-point times: taken as instantaneous";
    return times;
  }
  if (cloud.time.size() != cloud.points.size()) {
    times.warning = "not one per-point time per point: taken as instantaneous";
    return times;
  }
  const SweepTiming timing = SweepTiming::fromConfig(config.sensor, TimeSource::field);
  float earliest = 0.0f;
  float latest = 0.0f;
  bool first = true;
  for (float time : cloud.time) {
    if (!timing.withinSweep(time)) {
      ++times.outside_sweep;
      continue;
    }
    earliest = first ? time : std::min(earliest, time);
    latest = first ? time : std::max(latest, time);
    first = false;
  }
  if (2 * times.outside_sweep > cloud.time.size()) {
    times.warning = "per-point times mostly outside the sweep (a wrong unit or clock?): taken as instantaneous";
    times.outside_sweep = 0;
    return times;
  }
  if (earliest == latest) {
    times.warning = "per-point times all equal: taken as instantaneous";
    times.outside_sweep = 0;
    return times;
  }
  times.source = TimeSource::field;
  times.reference = 0.5 * (static_cast<double>(earliest) + latest);
  times.farthest = 0.5 * (static_cast<double>(latest) - earliest);
  if (times.outside_sweep > 0) times.warning = "points with a time outside the sweep (NaN, jumps) dropped";
  return times;
}

bool changesRegistration(const Vector6d& from, const Vector6d& to, double farthest, const RegistrationConfig& config) {
  const Vector6d change = (to - from) * farthest;
  return change.head<3>().norm() > config.converged_translation || change.tail<3>().norm() > config.converged_rotation;
}

Vector6d sweepVelocity(const Eigen::Isometry3d& increment, double dt) {
  if (!(dt > 0.0)) return Vector6d::Zero();
  return logSE3(increment) / dt;
}

double motionInterval(double stamp_interval, TimeSource source, const SensorConfig& sensor) {
  if (source != TimeSource::azimuth) return stamp_interval;
  const double period = 1.0 / sensor.rotation_rate_hz;
  return std::max(1.0, std::round(stamp_interval / period)) * period;
}

}  // namespace elo
