// A spinning multi-beam LiDAR: beams at the elevations of the sensor's table, fired together at each
// of `azimuth_steps` azimuths per revolution. Each return has Gaussian range noise, weak echoes (dark,
// oblique or far surfaces) are lost more often, some returns drop out at random, nothing comes back
// from the sky or from beyond max_range, and the intensity falls with the angle of incidence.
#pragma once

#include <Eigen/Geometry>
#include <cstdint>
#include <functional>
#include <vector>

#include "elo/config.hpp"
#include "elo/sim/rng.hpp"
#include "elo/sim/scene.hpp"
#include "elo/types.hpp"

namespace elo::sim {

// How a sweep with motion (LidarOptions::deskewed false) tells when each point was fired, as recorded
// data does. The scan's reference instant is where its stamp and its ground-truth pose lie.
enum class TimeConvention {
  // Each point carries its firing time in `time`, relative to the stamp, which is the sweep's start (a
  // ROS driver's per-point time field): times lie in [0, sweep duration). Reference: the stamp.
  field,
  // No per-point times, as in a KITTI .bin: a point's time follows from its azimuth (KITTI's HDL-64E,
  // the sensor config's default: clockwise seen from above, the sweep starting and ending straight
  // behind). Reference: mid-sweep, when the sensor faces forward; the stamp lies there.
  azimuth,
};

struct LidarOptions {
  double dropout_probability = 0.01;  // chance that any return is lost (dust, spray, ...)
  // A return's echo strength is reflectivity * cos(incidence) * (10 m / range)^2; it is detected with
  // probability 1 - exp(-strength / detection_threshold). The default thins the road beyond about
  // 50 m as on a real HDL-64E while walls stay visible to max range; 0 detects every echo.
  double detection_threshold = 1e-4;
  // true: the whole sweep is taken at its start pose (no motion distortion) and its points carry no
  // times, which a deskew would only misuse; false: each firing from the pose at its own time, as a
  // real spinning sensor does while the vehicle moves, with the times told by `time_convention`.
  bool deskewed = true;
  TimeConvention time_convention = TimeConvention::field;
  // Clutter that makes neighbouring pixels of a real scan lie on different surfaces; both are off by
  // default. foliage_depth: the mean depth (m, exponential, at most three times the mean) that a beam
  // reaches into leaves before it echoes. mixed_pixel_probability: the chance that a return beside a
  // depth edge (a jump of more than 0.5 m to the next firing of its beam, not a smooth slope) comes
  // back from anywhere between the two surfaces, as when the beam's footprint straddles the edge.
  double foliage_depth = 0.0;
  double mixed_pixel_probability = 0.0;
  // The systematic per-laser errors that a factory calibration leaves in a multi-beam sensor: each
  // laser reads long or short by its own constant range offset, and points off its nominal elevation
  // by its own constant angle, while the points are still computed along the nominal elevation. They
  // make neighbouring rows of the range image disagree by the same step on every scan, as the
  // "layered misalignment" reported for the HDL-64E S2 does. Each laser's errors are Gaussian with
  // these standard deviations (m and degrees), drawn once per unit; both off by default.
  double beam_range_bias = 0.0;
  double beam_elevation_error = 0.0;
  // A unit whose distance calibration is off as a whole: every laser reads every range this much long
  // (m, within +-1; negative: short), on top of its own offset above. 5 cm bend a simulated drive's drift
  // through the surfaces near the sensor, each seen from a new angle every scan (docs/real_drives.md).
  // 0 by default.
  double range_offset = 0.0;
  // The lasers of the lower half of the field (the HDL-64E's lower block) fire from this much lower (m)
  // than the points say, so that everything they see reads that much higher: the road near the sensor,
  // which only they reach, lies that much above the road farther out, as it does by 2-4 cm on KITTI's
  // HDL-64E (docs/real_drives.md). 0 by default.
  double lower_block_rise = 0.0;
  // The car the sensor is mounted on, in the sensor frame: beams that meet it return nothing (its
  // surfaces lie inside min_range). Empty: a sensor floating free.
  std::vector<Shape> vehicle_body = roofMountedCar();

  // An estate car under a roof-mounted sensor 1.73 m above the road (KITTI's Passat): the rounded
  // cabin under the sensor, and the lower bonnet and boot that hide the road close in front and behind.
  static std::vector<Shape> roofMountedCar();
};

// A sweep with the kind of surface behind each point (tests and statistics; not written out).
struct SimulatedScan {
  PointCloud cloud;
  std::vector<SurfaceKind> surface;
};

class Lidar {
 public:
  // The noise is sensor.range_noise_stddev; `unit_seed` draws the lasers' calibration errors. Throws
  // std::invalid_argument for an unusable sensor.
  Lidar(const SensorConfig& sensor, const LidarOptions& options, uint64_t unit_seed = 0);

  // One revolution starting at `start`, step 0 at sensor.sweep_start_azimuth_deg, turning as
  // sensor.clockwise says (by default: from straight behind, clockwise seen from above).
  // `sensor_pose_at(time)` gives the sensor in the world frame; points are in the sensor frame of their
  // firing, in firing order, with `ring` (0 = top beam). The cloud's stamp is the reference instant,
  // start + referenceOffset(); its `time` (offset from the stamp) is filled only for a sweep with
  // motion in the field convention. `seed` draws this sweep's noise and dropouts.
  SimulatedScan sweep(const RayCaster& scene, const std::function<Eigen::Isometry3d(double)>& sensor_pose_at,
                      double start, uint64_t seed) const;

  // The reference instant's offset from the sweep's start: half a sweep for a sweep with motion in the
  // azimuth convention, else 0.
  double referenceOffset() const;

  int beamCount() const { return static_cast<int>(beams_.size()); }
  int azimuthSteps() const { return static_cast<int>(azimuth_cos_.size()); }
  double sweepDuration() const { return 1.0 / sensor_.rotation_rate_hz; }
  // Unit direction of a firing in the sensor frame, at the beam's nominal elevation: the direction
  // its points are reported along.
  Eigen::Vector3d direction(int beam, int step) const;
  const SensorConfig& sensor() const { return sensor_; }

 private:
  struct Return {
    double range = 0.0;  // exact distance to the surface, 0 for none
    float intensity = 0.0f;
    SurfaceKind kind = SurfaceKind::ground;
  };
  double firingTime(int step) const { return step * sweepDuration() / azimuthSteps(); }
  std::vector<Return> castAll(const RayCaster& scene, const std::vector<Eigen::Isometry3d>& poses) const;
  SimulatedScan addNoise(const std::vector<Return>& returns, double start, uint64_t seed) const;
  // The range of `result` with the clutter of LidarOptions; `previous` and `next` are the firings of its
  // beam before and after it.
  double clutteredRange(const Return& previous, const Return& result, const Return& next, Rng& rng) const;
  static bool atDepthEdge(const Return& previous, const Return& result, const Return& next);
  bool detected(const Return& result, Rng& rng) const;
  bool hitsVehicle(const Eigen::Vector3d& direction) const;

  SensorConfig sensor_;
  LidarOptions options_;
  struct Beam {
    Eigen::Vector2d nominal;  // (cos, sin) of the elevation in the sensor's table
    Eigen::Vector2d actual;   // (cos, sin) of the elevation the laser really fires at
    double range_offset = 0.0;  // m that the laser adds to every range it reads
    double height = 0.0;        // m above the sensor's origin that the laser fires from
  };
  static std::vector<Beam> drawBeams(const SensorConfig& sensor, const LidarOptions& options, uint64_t unit_seed);
  // Unit direction that a firing's ray really takes.
  Eigen::Vector3d actualDirection(int beam, int step) const;

  std::vector<Beam> beams_;
  std::vector<double> azimuth_cos_;
  std::vector<double> azimuth_sin_;
  std::vector<bool> hidden_by_vehicle_;  // per firing (step-major, like the returns)
};

}  // namespace elo::sim
