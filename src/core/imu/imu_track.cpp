#include "elo/imu/imu_track.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <vector>

#include "elo/se3.hpp"

namespace elo {

namespace {

constexpr double kDegToRad = M_PI / 180.0;
constexpr double kClockJump = 1.0;  // s a sample may lie before the last one before it restarts the track
// The bias estimate starts as a mean of the first scans' with this many zeros before them: no one
// registration, the first after a start least of all, sets it alone.
constexpr size_t kBiasPriorScans = 9;

Eigen::Vector3d vectorOf(const std::vector<double>& values) { return {values[0], values[1], values[2]}; }

Eigen::Matrix3d rotationOf(const Eigen::Vector3d& turn) {
  const double angle = turn.norm();
  return angle > 0.0 ? Eigen::AngleAxisd(angle, turn / angle).toRotationMatrix() : Eigen::Matrix3d::Identity();
}

bool finite(const ImuSample& sample) {
  return std::isfinite(sample.stamp) && sample.angular_velocity.allFinite() && sample.specific_force.allFinite();
}

}  // namespace

Eigen::Matrix3d lidarFromImuRotation(const ImuConfig& config) {
  const Eigen::Vector3d rpy = vectorOf(config.rotation_deg) * kDegToRad;
  return (Eigen::AngleAxisd(rpy.z(), Eigen::Vector3d::UnitZ()) * Eigen::AngleAxisd(rpy.y(), Eigen::Vector3d::UnitY()) *
          Eigen::AngleAxisd(rpy.x(), Eigen::Vector3d::UnitX()))
      .toRotationMatrix();
}

ImuTrack::ImuTrack(const ImuConfig& config)
    : max_gap_(2.0 / config.min_rate_hz),
      gyro_limit_(config.gyro_limit_dps * kDegToRad),
      // Without the accelerometers, their saturation does not touch the gyro's samples.
      accel_limit_(config.accelerometer ? config.accel_limit : std::numeric_limits<double>::infinity()),
      time_offset_(config.time_offset),
      gyro_bias_(config.gyro_bias.size() == 3 ? vectorOf(config.gyro_bias) : Eigen::Vector3d::Zero()),
      accel_bias_(config.accel_bias.size() == 3 ? vectorOf(config.accel_bias) : Eigen::Vector3d::Zero()),
      lidar_from_imu_(config.rotation_deg.size() == 3 ? lidarFromImuRotation(config) : Eigen::Matrix3d::Identity()),
      bias_time_constant_(config.bias_time_constant) {}

void ImuTrack::setMount(const ImuConfig& config) { lidar_from_imu_ = lidarFromImuRotation(config); }

std::string ImuTrack::add(const ImuSample& sample) {
  std::string issue;
  if (!finite(sample)) {
    issue = imu_issue::kNotFinite;
  } else if (sample.angular_velocity.cwiseAbs().maxCoeff() >= gyro_limit_) {
    issue = imu_issue::kSaturated;
  } else if (sample.specific_force.cwiseAbs().maxCoeff() >= accel_limit_) {
    issue = imu_issue::kAccelSaturated;
  } else if (!samples_.empty() && sample.stamp + time_offset_ <= samples_.back().stamp) {
    // Far behind: a bag played again or a clock reset, as the odometry's reset() takes a scan stamped
    // before the last; the samples held describe another time.
    if (sample.stamp + time_offset_ < samples_.back().stamp - kClockJump) {
      samples_.clear();
      ++dropped_[imu_issue::kClockJump];
    } else {
      issue = imu_issue::kOutOfOrder;
    }
  }
  if (!issue.empty()) {
    ++dropped_[issue];
    return issue;
  }
  ImuSample taken = sample;
  taken.stamp += time_offset_;
  taken.angular_velocity -= gyro_bias_;
  taken.specific_force -= accel_bias_;
  samples_.push_back(taken);
  ++taken_;
  return {};
}

std::string ImuTrack::rotation(double from, double to, Eigen::Matrix3d& rotation) const {
  const auto before = [](const ImuSample& sample, double time) { return sample.stamp < time; };
  if (samples_.empty() || samples_.front().stamp > from || samples_.back().stamp < to) return imu_issue::kNotCovered;
  // The last sample at or before `from`, then every interval between samples up to `to`, each integrated
  // over its part within [from, to] by the mean of the rates (linear between the samples) at its ends.
  size_t i = static_cast<size_t>(std::lower_bound(samples_.begin(), samples_.end(), from, before) - samples_.begin());
  if (i == samples_.size() || samples_[i].stamp > from) --i;
  Eigen::Matrix3d imu_rotation = Eigen::Matrix3d::Identity();
  for (; i + 1 < samples_.size() && samples_[i].stamp < to; ++i) {
    const double t0 = samples_[i].stamp;
    const double t1 = samples_[i + 1].stamp;
    if (t1 - t0 > max_gap_) return imu_issue::kGap;
    const double a = std::max(from, t0);
    const double b = std::min(to, t1);
    if (b <= a) continue;
    const Eigen::Vector3d& w0 = samples_[i].angular_velocity;
    const Eigen::Vector3d& w1 = samples_[i + 1].angular_velocity;
    const auto rate = [&](double t) -> Eigen::Vector3d { return w0 + (w1 - w0) * ((t - t0) / (t1 - t0)) - learnt_bias_; };
    imu_rotation = imu_rotation * rotationOf(0.5 * (rate(a) + rate(b)) * (b - a));
  }
  rotation = lidar_from_imu_ * imu_rotation * lidar_from_imu_.transpose();
  return {};
}

Eigen::Vector3d ImuTrack::rateAt(double time) const {
  const auto before = [](const ImuSample& sample, double t) { return sample.stamp < t; };
  size_t i = static_cast<size_t>(std::lower_bound(samples_.begin(), samples_.end(), time, before) - samples_.begin());
  i = std::min(std::max<size_t>(i, 1), samples_.size() - 1);
  const ImuSample& a = samples_[i - 1];
  const ImuSample& b = samples_[i];
  const double share = b.stamp > a.stamp ? (time - a.stamp) / (b.stamp - a.stamp) : 0.0;
  return lidar_from_imu_ * (a.angular_velocity + (b.angular_velocity - a.angular_velocity) * share - learnt_bias_);
}

std::string ImuTrack::sweepRotation(double reference, double from, double to, GyroSweep& sweep) const {
  constexpr int kKnots = GyroSweep::kIntervals + 1;
  // The last knot at `to` itself: the samples cover that much, and maybe not a rounding beyond.
  const auto knot = [&](int k) {
    return k == GyroSweep::kIntervals ? to : from + k * (to - from) / GyroSweep::kIntervals;
  };
  // Each knot's frame in the first knot's, interval after interval, then in the reference's.
  std::vector<Eigen::Matrix3d> from_first(kKnots, Eigen::Matrix3d::Identity());
  for (int k = 1; k < kKnots; ++k) {
    Eigen::Matrix3d interval;
    const std::string issue = rotation(knot(k - 1), knot(k), interval);
    if (!issue.empty()) return issue;
    from_first[k] = from_first[k - 1] * interval;
  }
  Eigen::Matrix3d reference_from_first;
  const std::string issue = rotation(from, reference, reference_from_first);
  if (!issue.empty()) return issue;
  sweep.first = from - reference;
  sweep.last = to - reference;
  sweep.rotations.clear();
  sweep.rates.clear();
  for (int k = 0; k < kKnots; ++k) {
    sweep.rotations.push_back(reference_from_first.transpose() * from_first[k]);
    sweep.rates.push_back(rateAt(knot(k)));
  }
  return {};
}

GyroMotion ImuTrack::scanMotion(double previous_reference, double reference, double sweep_from,
                                double sweep_to, double stamp) const {
  GyroMotion motion;
  Eigen::Matrix3d over_sweep;
  motion.fallback = rotation(previous_reference, reference, motion.rotation);
  if (motion.fallback.empty()) motion.fallback = rotation(sweep_from, sweep_to, over_sweep);
  if (motion.fallback.empty()) motion.fallback = sweepRotation(reference, sweep_from, sweep_to, motion.sweep);
  motion.known = motion.fallback.empty();
  if (!motion.known) return motion;
  motion.sweep_rate = logSO3(over_sweep) / (sweep_to - sweep_from);
  // A stamp beyond the samples (a driver's stamp past the sweep) turns at the sweep's mean rate.
  if (rotation(std::min(stamp, reference), std::max(stamp, reference), motion.stamp_rotation).empty()) {
    if (stamp < reference) motion.stamp_rotation.transposeInPlace();
  } else {
    motion.stamp_rotation = rotationOf((stamp - reference) * motion.sweep_rate);
  }
  return motion;
}

std::string ImuTrack::preintegrate(double from, double to, Preintegration& motion) const {
  const auto before = [](const ImuSample& sample, double time) { return sample.stamp < time; };
  if (samples_.empty() || samples_.front().stamp > from || samples_.back().stamp < to) return imu_issue::kNotCovered;
  size_t i = static_cast<size_t>(std::lower_bound(samples_.begin(), samples_.end(), from, before) - samples_.begin());
  if (i == samples_.size() || samples_[i].stamp > from) --i;
  // In the IMU's axes, then turned into the LiDAR's; each piece by its midpoint's rotation.
  Preintegration imu;
  imu.duration = to - from;
  for (; i + 1 < samples_.size() && samples_[i].stamp < to; ++i) {
    const ImuSample& s0 = samples_[i];
    const ImuSample& s1 = samples_[i + 1];
    if (s1.stamp - s0.stamp > max_gap_) return imu_issue::kGap;
    const double a = std::max(from, s0.stamp);
    const double b = std::min(to, s1.stamp);
    if (b <= a) continue;
    const auto at = [&](const Eigen::Vector3d& v0, const Eigen::Vector3d& v1, double t) -> Eigen::Vector3d {
      return v0 + (v1 - v0) * ((t - s0.stamp) / (s1.stamp - s0.stamp));
    };
    const double h = b - a;
    const double middle = 0.5 * (a + b);
    const Eigen::Vector3d rate = at(s0.angular_velocity, s1.angular_velocity, middle) - learnt_bias_;
    const Eigen::Matrix3d turn_at_middle = imu.rotation * rotationOf(0.5 * h * rate);
    const Eigen::Vector3d force = turn_at_middle * at(s0.specific_force, s1.specific_force, middle);
    imu.position += imu.velocity * h + 0.5 * force * h * h;
    imu.velocity += force * h;
    imu.position_by_bias += imu.velocity_by_bias * h + 0.5 * turn_at_middle * h * h;
    imu.velocity_by_bias += turn_at_middle * h;
    imu.rotation = imu.rotation * rotationOf(h * rate);
  }
  const Eigen::Matrix3d& axes = lidar_from_imu_;
  motion.duration = imu.duration;
  motion.rotation = axes * imu.rotation * axes.transpose();
  motion.velocity = axes * imu.velocity;
  motion.position = axes * imu.position;
  motion.velocity_by_bias = axes * imu.velocity_by_bias * axes.transpose();
  motion.position_by_bias = axes * imu.position_by_bias * axes.transpose();
  return {};
}

void ImuTrack::learnBias(const Eigen::Matrix3d& gyro, const Eigen::Matrix3d& registered, double dt) {
  if (bias_time_constant_ <= 0.0 || dt <= 0.0) return;
  // The gyro turned by `gyro` where the LiDAR turned by `registered`: its rate was high by the rotation
  // between them over dt, in the IMU's axes.
  const Eigen::Vector3d excess = lidar_from_imu_.transpose() * logSO3(registered.transpose() * gyro) / dt;
  ++bias_updates_;
  const double gain = std::max(1.0 / static_cast<double>(bias_updates_ + kBiasPriorScans), dt / bias_time_constant_);
  learnt_bias_ += gain * excess;
}

void ImuTrack::forgetBefore(double stamp) {
  while (samples_.size() > 1 && samples_[1].stamp <= stamp) samples_.pop_front();
}

}  // namespace elo
