// The IMU's samples the odometry holds, and what it reads of them (docs/imu.md): the LiDAR's rotation
// between two instants by the integrated gyro, its mean turn rate over a sweep and its rotation through
// the sweep, in the LiDAR's frame.
// A rigid mount turns both sensors alike, so only the mount's rotation matters here, not its offset.
#pragma once

#include <Eigen/Geometry>
#include <deque>
#include <map>
#include <optional>
#include <string>

#include "elo/config.hpp"
#include "elo/imu/gyro_sweep.hpp"

namespace elo {

// One sample, as `imu.txt` lines and sensor_msgs/Imu give it.
struct ImuSample {
  double stamp = 0.0;  // s on the IMU's clock (imu.time_offset puts it on the scans')
  Eigen::Vector3d angular_velocity = Eigen::Vector3d::Zero();  // rad/s, IMU axes
  Eigen::Vector3d specific_force = Eigen::Vector3d::Zero();    // m/s^2, gravity included, IMU axes
};

// Why a sample was dropped, or why the gyro could not turn a scan (a fallback to the LiDAR-only prior):
// the keys of ImuTrack::droppedCounts() and of Odometry::imuFallbackCounts().
namespace imu_issue {
inline constexpr char kNotFinite[] = "IMU sample not finite";
inline constexpr char kOutOfOrder[] = "IMU sample out of order";
inline constexpr char kClockJump[] = "IMU clock went back over a second: samples before it forgotten";
inline constexpr char kSaturated[] = "IMU sample saturated (imu.gyro_limit_dps)";
inline constexpr char kAccelSaturated[] = "IMU sample saturated (imu.accel_limit)";
inline constexpr char kNotCovered[] = "no IMU samples over the scan";
inline constexpr char kGap[] = "IMU gap over the scan (imu.min_rate_hz)";
}  // namespace imu_issue

// The IMU's state for a report (the node's diagnostics): Odometry::imuStatus(). Open to more (the
// accelerometers' gravity and bias).
struct ImuStatus {
  size_t samples_taken = 0;                  // since the start, those dropped not counted
  std::map<std::string, size_t> dropped;     // samples, by imu_issue
  std::map<std::string, size_t> fallbacks;   // scans the gyro could not turn, by imu_issue
  Eigen::Vector3d gyro_bias = Eigen::Vector3d::Zero();  // rad/s, the IMU's axes: imu.gyro_bias and the bias learnt
  // The accelerometers' filter (imu.accelerometer; InertialFilter), once it has started: gravity in the
  // odometry's world frame (the first scan's, m/s^2) and the accelerometers' bias (m/s^2, the IMU's axes:
  // imu.accel_bias and the bias learnt).
  bool gravity_known = false;
  Eigen::Vector3d gravity = Eigen::Vector3d::Zero();
  Eigen::Vector3d accel_bias = Eigen::Vector3d::Zero();
  // Intervals whose specific force the filter did not take, their translation missing the registered one
  // (imu.accel_gate): the scans after each on the LiDAR's translation until the velocity is registered again.
  size_t accel_gated = 0;
  // Roll and pitch against gravity (TiltHold): how far the accelerometers' gravity over the last ten
  // seconds is from the first ten seconds' (deg; nullopt before both), and the scans turned back towards
  // it (imu.tilt_hold_deg).
  std::optional<double> tilt_deg;
  size_t tilt_held = 0;
};

// What the gyro says of one scan: the LiDAR's rotation since the scan before (between the two reference
// instants), its mean rate over the scan's sweep, its rotation through the sweep and at the scan's stamp,
// in the LiDAR's frame.
// Known when the samples cover both; else `fallback` says why (empty without imu.enabled).
struct GyroMotion {
  bool known = false;
  Eigen::Matrix3d rotation = Eigen::Matrix3d::Identity();
  Eigen::Vector3d sweep_rate = Eigen::Vector3d::Zero();  // rad/s
  GyroSweep sweep;
  // The frame at the scan's stamp in the frame at its reference instant (the reported pose's turn).
  Eigen::Matrix3d stamp_rotation = Eigen::Matrix3d::Identity();
  std::string fallback;
};

// The IMU's motion between two instants in the LiDAR frame at the first (its axes; the IMU's own point,
// not the LiDAR's origin), the specific force integrated without gravity: what the accelerometers say
// of a scan's translation (InertialFilter). `velocity` and `position` are less the learnt accelerometer
// bias b (LiDAR axes) by `velocity_by_bias` b and `position_by_bias` b.
struct Preintegration {
  double duration = 0.0;                                              // s
  Eigen::Matrix3d rotation = Eigen::Matrix3d::Identity();             // the LiDAR's, by the gyro
  Eigen::Vector3d velocity = Eigen::Vector3d::Zero();                 // m/s: integral of R(t) f(t)
  Eigen::Vector3d position = Eigen::Vector3d::Zero();                 // m: its integral
  Eigen::Matrix3d velocity_by_bias = Eigen::Matrix3d::Zero();         // integral of R(t), s
  Eigen::Matrix3d position_by_bias = Eigen::Matrix3d::Zero();         // its integral, s^2
};

class ImuTrack {
 public:
  explicit ImuTrack(const ImuConfig& config);

  // Takes the mount of `config` (imu.position, imu.rotation_deg) in place of the one it was built with: a
  // mount known only once running (the ROS node's, from TF). The samples held are read through it from now on.
  void setMount(const ImuConfig& config);

  // Takes a sample; returns empty, or why it was dropped (counted in droppedCounts()). A sample over a
  // second before the last one (a bag played again) restarts the track from it, counted as kClockJump.
  std::string add(const ImuSample& sample);
  // The LiDAR frame at `to` in the LiDAR frame at `from` (s, the scans' clock, from <= to), its rotation
  // only, by the gyro integrated with its rate linear between samples, into `rotation`. Returns why it
  // cannot be, or empty: samples must lie at or before `from` and at or after `to`, none of them further
  // apart than two periods at imu.min_rate_hz.
  std::string rotation(double from, double to, Eigen::Matrix3d& rotation) const;
  // The LiDAR's rotation through [from, to] (a sweep, s on the scans' clock) in its frame at `reference`
  // (within it), and its rate, at the knots of `sweep` (GyroSweep::kIntervals + 1, evenly spread, their
  // times from `reference`): rotation() between the knots, the rate linear between samples. Returns why
  // it cannot be, or empty, as rotation() does.
  std::string sweepRotation(double reference, double from, double to, GyroSweep& sweep) const;
  // rotation() between the reference instants of two scans, the mean rate and sweepRotation() over the
  // later one's sweep, and its rotation between its reference instant and its `stamp` (at the mean rate
  // where the samples do not reach the stamp).
  GyroMotion scanMotion(double previous_reference, double reference, double sweep_from, double sweep_to,
                        double stamp) const;
  // The gyro and the accelerometers integrated from `from` to `to` (the scans' clock), their rate and
  // specific force linear between samples, into `motion`; returns why it cannot be, as rotation() does.
  std::string preintegrate(double from, double to, Preintegration& motion) const;
  // Moves the gyro's bias estimate towards what makes its rotation `gyro` (from rotation()) over `dt`
  // seconds the registered rotation `registered` (both the LiDAR's), by imu.bias_time_constant.
  void learnBias(const Eigen::Matrix3d& gyro, const Eigen::Matrix3d& registered, double dt);
  // The gyro's bias estimated online (rad/s, the IMU's axes), on top of imu.gyro_bias.
  const Eigen::Vector3d& learntBias() const { return learnt_bias_; }
  // imu.accel_bias (m/s^2, the IMU's axes), removed from every sample taken.
  const Eigen::Vector3d& accelBiasSet() const { return accel_bias_; }
  // Forgets the samples before `stamp` (the scans' clock) but the last one at or before it.
  void forgetBefore(double stamp);

  const std::map<std::string, size_t>& droppedCounts() const { return dropped_; }
  size_t size() const { return samples_.size(); }
  // Samples taken since the start (dropped ones not counted), and the gyro's whole bias estimate
  // (imu.gyro_bias and learntBias(), rad/s, the IMU's axes).
  size_t takenCount() const { return taken_; }
  Eigen::Vector3d biasEstimate() const { return gyro_bias_ + learnt_bias_; }

 private:
  // The gyro's rate at `time` (within the samples), linear between samples, its bias removed, LiDAR axes.
  Eigen::Vector3d rateAt(double time) const;

  double max_gap_;
  double gyro_limit_;  // rad/s
  double accel_limit_;  // m/s^2
  double time_offset_;
  Eigen::Vector3d gyro_bias_;
  Eigen::Vector3d accel_bias_;
  Eigen::Matrix3d lidar_from_imu_;
  double bias_time_constant_;
  Eigen::Vector3d learnt_bias_ = Eigen::Vector3d::Zero();
  size_t bias_updates_ = 0;
  size_t taken_ = 0;
  std::deque<ImuSample> samples_;  // the scans' clock, biases removed, in time order
  std::map<std::string, size_t> dropped_;
};

// The IMU's axes in the LiDAR frame from imu.rotation_deg (roll, pitch, yaw about x, y, z).
Eigen::Matrix3d lidarFromImuRotation(const ImuConfig& config);

}  // namespace elo
