// Every parameter of the pipeline, with its default. This file is the one source of defaults: YAML files
// and ROS parameters only override what is written here (see parameters() below), and the defaults are
// the values of Zheng & Zhu, "Efficient LiDAR Odometry for Autonomous Driving", for an HDL-64E.
#pragma once

#include <functional>
#include <stdexcept>
#include <string>
#include <variant>
#include <vector>

namespace elo {

// Which cost terms the registration uses (paper Table II); `fused` is the method, the others are the
// ablations the paper compares against.
enum class CostTerms { fused, spherical_all, spherical_nonground, bev_ground };
// How normals of the spherical range image are computed (paper Table III).
enum class NormalMethod { range_adaptive, eigen, cross_product };
enum class RegistrationMode { frame_to_model, frame_to_frame };
enum class MotionPrior { constant_acceleration, constant_velocity, none };
enum class BackendKind { cpu, cuda };
// Where each point's firing time comes from, for deskewing (docs/deskew.md): nowhere (every scan is
// instantaneous), the cloud's own per-point times (PointCloud::time), or the point's azimuth along the
// sensor's rotation (sensor.rotation_rate_hz, sensor.clockwise, sensor.sweep_start_azimuth_deg).
enum class TimeSource { none, field, azimuth };
// Which beam a driver's `ring` 0 is: velodyne_pointcloud counts rings up from the lowest beam, ouster_ros
// down from the highest; `table`: ring k is entry k of sensor.beam_elevations_deg, for a driver that
// numbers its rings in an order that is not the beams' (Hesai's QT128: its correction file's channels).
enum class RingZero { bottom, top, table };

// Sec. III-B.1, Eq. 3-4: the sensor and its spherical range image.
struct SensorConfig {
  std::string name = "hdl64";
  int image_width = 2048;          // w_S: azimuth columns
  int image_height = 80;           // h_S: elevation rows
  // The image spans a little more than the beams (+2 .. -24.33 deg), so that no beam sits on an image
  // edge where half its points would fall out; +3 / -25 deg is KITTI's customary range image.
  double fov_up_deg = 3.0;         // f_up: elevation of the top of the image
  double fov_down_deg = -25.0;     // f_down: elevation of the bottom (negative: below the horizon)
  double min_range = 2.5;          // closer returns hit the vehicle itself
  double max_range = 120.0;
  // Rotates every point's elevation up by this angle. KITTI's HDL-64E intrinsics bend the scan; the
  // paper (after IMLS-SLAM) corrects by 0.195 deg. Zero for any other data.
  double elevation_correction_deg = 0.0;
  // Nominal elevation of each beam, top to bottom (with ring_zero table: in the driver's ring order); the
  // simulator fires these. Empty means `beam_count` beams spread evenly over the field of view.
  std::vector<double> beam_elevations_deg = hdl64BeamElevations();
  int beam_count = 64;
  // How the `ring` field numbers the beams (ringElevations()); the simulator numbers them the same way.
  RingZero ring_zero = RingZero::bottom;
  int azimuth_steps = 2083;        // firings per revolution (simulator)
  // Revolutions per second: the simulator's sweep, the times deskew.time_source azimuth gives, and the
  // window per-point times must lie in (one sweep either side of the stamp, with a margin).
  double rotation_rate_hz = 10.0;
  // The sweep of deskew.time_source azimuth (and of the simulator): the direction of rotation seen from
  // above (x forward, y left, z up) and the azimuth (deg, counter-clockwise from x) where each sweep
  // starts and ends. KITTI's HDL-64E: clockwise, starting straight behind (180), so that the forward
  // direction is fired mid-sweep.
  bool clockwise = true;
  double sweep_start_azimuth_deg = 180.0;
  double range_noise_stddev = 0.02;  // metres (simulator)

  // The HDL-64E S2 table: an upper block of 32 lasers from +2 deg to -8.33 deg and a lower block of
  // 32 from -8.83 deg to -24.33 deg (the field of view KITTI's scans show).
  static std::vector<double> hdl64BeamElevations();
};

// Sec. III-C.1: ground segmentation on the columns of the range image.
struct GroundConfig {
  double sensor_height = 1.73;  // h_g: the sensor above the road, so the road lies at z = -h_g
  double band_above = 0.5;      // delta_h1: a ground point lies below -h_g + band_above
  double band_below = 1.0;      // delta_h2: ... and above -h_g - band_below
  double max_slope_deg = 5.0;   // delta_theta: slope to the next valid pixel up and down the column
  // Rise (m) allowed on top of delta_theta's. Within about 7 m of an HDL-64E, neighbouring rings meet
  // the road 0.1-0.3 m apart, where 5 degrees allows 1-2 cm: less than the range noise puts between
  // them, so without it half of the road within 5 m is labelled non-ground (docs/ground_segmentation.md).
  double rise_tolerance = 0.03;
  // Within this range (m) of the sensor, every point of the ground band is ground whatever its slope, and
  // stays out of the scan's ground map: out of both terms and both models. 0: off. KITTI's HDL-64E reads
  // the road within 10 m 2-4 cm higher than the road beyond (docs/real_drives.md).
  double min_range = 0.0;
};

// Sec. III-B.3-4, Eq. 10-12: normals of the non-ground range image.
struct NormalConfig {
  NormalMethod method = NormalMethod::range_adaptive;
  double search_size = 0.3;       // delta: metric extent of the neighbourhood window
  int min_window_width = 5;       // l_x^min
  int max_window_width = 13;      // l_x^max
  int min_window_height = 3;      // l_y^min
  int max_window_height = 7;      // l_y^max
  double outlier_distance = 0.5;  // sigma_r: a neighbour farther than this from the centre is an outlier
  double plane_distance = 0.5;    // sigma_z: point-to-plane distance that drops a neighbour at refit
  int min_neighbours = 5;         // fewer inliers than this (the centre included) give no normal
  // Curvature lambda3/(lambda1+lambda2+lambda3) above this is not planar; the paper selects planar
  // points by curvature without giving the threshold.
  double max_curvature = 0.1;
};

// Sec. III-C.2, Eq. 14-17: the bird's-eye-view map of ground points.
struct BevConfig {
  double cell_size = 0.1;     // s_x = s_y (m)
  double half_length = 120.0; // w_B: the map spans x in [-w_B, w_B) around the sensor
  double half_width = 60.0;   // h_B: ... and y in [-h_B, h_B)
  int normal_neighbours = 5;  // model points fitted for the normal of a ground correspondence
  int normal_patch_radius = 3;  // cells searched around the associated model cell
};

// Sec. III-A, Eq. 1-2: Gauss-Newton on SE(3) over w*E_S + (1-w)*E_G.
struct RegistrationConfig {
  CostTerms terms = CostTerms::fused;
  double nonground_weight = 0.7;  // w1; w = w1 * w2 with w2 from the two inlier ratios
  int max_iterations = 20;
  // Stop when the step, or the steps still to come predicted from the last two (registration.cpp), are below
  // both. 1e-4 m / 1e-5 rad moved the real drive by at most 1.0 mm over 22 m (step test alone, +1.4 iterations).
  double converged_translation = 5e-4;  // m
  double converged_rotation = 5e-5;     // rad
  double max_correspondence_distance = 1.0;  // m between the moved scan point and its model point
  double max_normal_angle_deg = 30.0;  // between a scan normal and its model normal
  int association_radius = 1;  // pixels searched around the projection for the closest model vertex
  // Scale (m) of the Geman-McClure kernel that down-weights large point-to-plane residuals (IRLS).
  // Correspondences at edges and corners carry residuals of centimetres even at the true pose and would
  // bias plain least squares; 0 gives the paper's plain least squares.
  double robust_kernel_scale = 0.1;
  // A non-ground correspondence whose scan point lies nearer than this (m) weighs its range over it; 0
  // weighs all alike (the paper). A pixel stands for a patch of surface growing with the square of its
  // range: weighed alike, a fence or an embankment beside the car outnumbers the scene around it and
  // held the heading of two real KITTI drives (docs/real_drives.md); config/kitti.yaml sets 45.
  double near_weight_range = 0.0;
  // A direction of motion whose share of the constraint (eigenvalue of the unit-consistent Hessian, see
  // degeneracy.hpp) is below this is degenerate: it is not solved and keeps the motion prior. 0 turns the
  // handling off. Smallest eigenvalue measured per scan (HDL-64E, simulated unless said): the tunnel
  // world 0.0014-0.0018 (forward) from 25 m past its portal on, up to 0.0071 over those 25 m; the highway
  // world 0.012 at the least (5th percentile 0.021; forward), the tunnel's open approach 0.010; urban 0.065,
  // country 0.033, parking 0.18; the 60 real scans 0.081. At 0.005 the portal's scans were solved on the few
  // returns from the mouth, and the forward velocity carried into the tunnel was about 1.5% off (0.95%
  // drift against 0.26% at 0.01). Flagging open road is cheap: on the highway, 0.02 flagged 9 of 300
  // scans for 0.124% drift against 0.126%.
  double degeneracy_threshold = 0.01;
};

// Sec. III-D: the model of three 2D maps.
struct ModelConfig {
  RegistrationMode mode = RegistrationMode::frame_to_model;
  double time_window = 10.0;  // tau_w (s): older model points are dropped
  // The closer point wins a pixel of the model, or a cell of a BEV map, only when it is closer by more
  // than this (m): then it is another surface in front (Sec. III-D). Offers within it are one surface
  // seen again, and the oldest of them stays (within one scan: the first). Taken literally, "closer
  // wins" keeps the nearest of the noisy ranges offered and pulls the maps' surfaces towards the sensor
  // (the non-ground model by 10 mm at 2 cm noise on the simulated urban drive), which drifts the
  // registration. 0 is the paper's literal rule.
  double same_surface_distance = 0.3;
  MotionPrior motion_prior = MotionPrior::constant_acceleration;
};

// Motion compensation (docs/deskew.md): every point is moved from the sensor frame of its firing instant
// to the scan's reference instant, under the sensor's velocity over the sweep. The reference instant is
// the cloud's stamp for `field` (time 0) and mid-sweep for `azimuth` (when the sensor faces the azimuth
// opposite the sweep's start: forward, for KITTI, whose ground truth refers to that instant).
struct DeskewConfig {
  // `field` is what ROS drivers deliver: Velodyne `time`, Ouster `t`, Hesai `timestamp`. A cloud without
  // usable times is processed as instantaneous, and counted (Odometry::warningCounts()).
  TimeSource time_source = TimeSource::field;
  // Refinement rounds within the registration: after each of its first Gauss-Newton steps, the scan
  // (deskewed under the last registered velocity) is deskewed again under the motion estimated so far
  // and the iterations go on. One round brings the deskew to the registered motion at no iterations of
  // its own (after the first step); further rounds change it by what one round changed the pose,
  // which is the prior's error times the sweep over the scan interval (docs/deskew.md).
  int rounds = 1;
};

// The drive's map (docs/map.md): elo_run --map, the node's ~save_map and `map` topic.
struct MapConfig {
  // Edge of a map voxel (m). Fine enough for curbs, poles and facades' relief; coarse enough that the
  // map costs about 0.13 GiB a kilometre of urban street (docs/map.md) and that a VLP-16's rings, 2 deg
  // apart (0.35 m at 10 m), still leave few empty voxels on a surface driven past. An HDL-64E's rings lie
  // 0.4 deg apart (0.14 m at 20 m).
  double voxel_size = 0.2;
  // The moving-object filter: a non-ground voxel is written only when this many of the scans the map
  // took (scan_stride) saw it. A car driving at v m/s stays in a voxel for (its length / v) s, 4-5 scans
  // at 10 m/s, 2-3 of them taken; a wall driven past is seen by tens of scans. Ground voxels are always
  // written (the road does not move, and a sparse sensor's rings cross a ground voxel only once or
  // twice). 1 writes every voxel.
  int min_observations = 3;
  // The map takes every n-th registered scan. At 10 Hz consecutive scans see the same surfaces from
  // 0.1-3 m apart: every second one still sees each surface many times over, at half the map's CPU
  // (docs/map.md measures both). 1 takes every scan.
  int scan_stride = 2;
};

struct RuntimeConfig {
  BackendKind backend = BackendKind::cpu;
  // With backend cuda and no usable GPU: run on the CPU backend with a warning instead of failing.
  bool backend_fallback = false;
  int threads = 0;  // 0: all hardware threads
};

// Localization on a saved map (docs/localization.md): the map rendered around the predicted pose into
// a second model, the scan registered against it, map -> odom corrected from accepted matches.
struct LocalizationConfig {
  double render_range = 80.0;    // m around the sensor whose map points are rendered each match
  double tile_size = 20.0;       // m: the map index's square tiles
  // Each map point covers a disc of this radius (m) in the range image, so that a map sampled sparser
  // than the image's pixels near the sensor leaves no holes for farther surfaces to show through.
  double splat_radius = 0.1;
  double normal_radius = 0.5;    // m: neighbours of a map point fitted for its normal when the file has none
  // A match is accepted when at least this share of the scan's features find a map correspondence
  // and their point-to-plane RMS is at most max_rms (m).
  double min_inlier_share = 0.5;
  double max_rms = 0.12;
  double max_correction = 1.0;   // m: a tracked match moving the pose further than this is refused
  // Refused or failed matches in a row that declare the vehicle lost; while lost, or while a refused hint
  // is carried, the scans from one search to the next.
  int lost_after = 10;
  // The initial-pose search around a hint: positions within search_radius (m) every search_step (m),
  // yaws within search_yaw_deg either side every search_yaw_step_deg.
  double search_radius = 2.5;
  double search_step = 1.0;
  double search_yaw_deg = 15.0;
  double search_yaw_step_deg = 5.0;
  int search_refined = 6;        // best-scored candidates registered to convergence
  // A search's winner must stand out: a refined candidate that converged elsewhere (half a search step or
  // yaw step away) and is acceptable too refuses the search when its inlier share comes within this of
  // the winner's (a repeated or featureless stretch of the map).
  double search_margin = 0.05;
};

// What the platform can do (docs/robustness.md#a-lost-track): a registration that moves the sensor
// faster, turns it faster or changes its velocity more than this between two scans, or whose
// correspondences collapse against the scans before, is refused: its pose is the motion prior's, it
// updates neither the model nor the velocity, and the next scan's motion is searched as at a start.
// Carried by hand, the odometry had accepted motions of kilometres a second that became the next scan's
// prior; the defaults fit cars (144 km/h, 0.8 g braking) and hand-held rigs (swung at 200 deg/s).
struct MotionConfig {
  double max_speed = 40.0;           // m/s; also the start search's reach along x
  double max_turn_rate_deg = 360.0;  // deg/s
  // m/s^2: the change of velocity from one registration to the next over their interval. 2 g: a car
  // brakes at 0.8 g, and a walker's steps and a trot's jolts, as scans 0.1 s apart see them, stay under
  // it; a wrong registration on a hand-held walk jumps by metres a scan (tens of g).
  double max_acceleration = 20.0;
  // s: how far a scan's stamp may lie from when it was taken. A velocity is a registered motion over
  // the stamps' interval, so a stamp error of e makes two consecutive velocities differ by up to
  // 2 e / dt of the speed without any acceleration: tolerated on top of max_acceleration. KITTI-raw
  // drives' times come rounded to 10 ms (0.10 and 0.11 s between scans): at 17 m/s that is 3.4 m/s.
  double stamp_jitter = 0.01;
  // A registration with fewer non-ground inliers than this share of the median of the last accepted
  // ones has lost the scene (a scan of another place, a blocked view).
  double min_inlier_share_of_recent = 0.3;
  // Refused registrations in a row after which the model restarts from the scan at hand, at the pose the
  // motion prior gives it: the old model no longer matches what the sensor sees.
  int restart_after = 5;
};

// The start in motion (docs/start_in_motion.md): a scan registered when no motion is known yet (the first
// registration after a start, a reset or a restart) has its motion searched for first, so that odometry
// started on a moving vehicle tracks from its second scan. Candidates lie along the sensor's x axis,
// forward and back, and in yaw; each is registered a few steps and scored by how well it fits.
struct StartSearchConfig {
  bool enabled = true;
  // The candidates along x reach motion.max_speed times the time between the two scans either way: 4 m
  // at 10 Hz.
  double step = 1.0;  // m between candidates along x: a candidate half a step off converges in its few steps
  // deg/s: the candidates in yaw reach this times the time between the scans either way (3 deg at 10 Hz).
  double max_yaw_rate_deg = 30.0;
  double yaw_step_deg = 3.0;  // deg between candidates in yaw
  // A candidate that ended elsewhere and scored within this of the winner makes the start ambiguous:
  // taken, counted and reported, as the scan does not tell the two motions apart.
  double margin = 0.02;
  // A scan more than this many usual intervals after the scan before follows a gap: the motion prior does
  // not hold across it, and its motion is searched on two lines, the velocity carried over the gap and
  // over one usual interval (a clock that jumped). The usual interval is the sensor's period
  // (1 / sensor.rotation_rate_hz), or the longer one the scans came at before (a throttled topic). Two
  // missed scans (3 periods) are a gap; one (2 periods) is bridged by the prior.
  double after_gap_periods = 2.5;
};

// An IMU beside the LiDAR (docs/imu.md): its gyro turns the motion prior and the deskew. Off by default,
// and off means today's poses bit for bit.
struct ImuConfig {
  bool enabled = false;
  // Where the IMU sits in the LiDAR's frame: its origin (m) and its axes as roll, pitch and yaw (deg,
  // rotations about the LiDAR's x, y and z in that order).
  std::vector<double> position = {0.0, 0.0, 0.0};
  std::vector<double> rotation_deg = {0.0, 0.0, 0.0};
  // s added to the IMU's stamps to put them on the scans' clock.
  double time_offset = 0.0;
  // Hz: the IMU's rate may not fall under this. Between two samples further apart than two of its
  // periods (40 ms at 50 Hz) the gyro is not integrated: the scans there fall back to the LiDAR-only prior.
  double min_rate_hz = 50.0;
  // deg/s: a sample with a rate at or beyond this on any axis is taken as saturated and dropped (consumer
  // MEMS units are built for 2000 deg/s, often set to less).
  double gyro_limit_dps = 2000.0;
  // rad/s, the IMU's axes: the gyro's bias at the start, subtracted from every sample.
  std::vector<double> gyro_bias = {0.0, 0.0, 0.0};
  // s: the gyro's bias is then estimated online against the LiDAR's registered rotations, each accepted
  // scan moving the estimate by dt / this of its difference (the first scans by more: a mean of theirs
  // with nine zeros before it, so that a turn-on bias is learnt within seconds). A consumer MEMS gyro's bias (0.5 deg/s) turned the deskew of a
  // car's sweeps enough to cost r_rel a fifth; the registration's noise (about 0.1 deg/s a scan) averages out
  // over this time. 0 keeps imu.gyro_bias as given.
  double bias_time_constant = 10.0;
  // Whether the accelerometers give the translation of the motion prior (docs/imu.md): the velocity
  // registered, carried on by the integrated specific force less the bias, plus gravity. False: the
  // translation is the LiDAR's prior (constant velocity or acceleration), the gyro still turns it.
  bool accelerometer = true;
  // m/s^2: a sample with a specific force at or beyond this on any axis is taken as saturated and dropped
  // (consumer MEMS units are built for 16 g, often set to 2-8 g).
  double accel_limit = 156.9;
  // m/s^2, the IMU's axes: the accelerometers' bias at the start, subtracted from every sample.
  std::vector<double> accel_bias = {0.0, 0.0, 0.0};
  // s: the accelerometers' bias is then estimated online against the LiDAR's registered translations, as
  // a random walk that may move by its prior (0.1 m/s^2) over about this long. 0 keeps imu.accel_bias.
  double accel_bias_time_constant = 100.0;
  // m: the gate on an interval's specific force. When the accelerometers' translation missed the registered
  // one by more than the LiDAR-only prior's did, plus this, the interval's samples are taken to mislead
  // (an impulse aliased into one sample, which a unit's anti-aliasing filter would have smoothed): the
  // filter does not take them, and the next scans' prior is the LiDAR's until the velocity is registered
  // again. The registrations' own noise stays within it (docs/imu.md, "The accelerometers").
  double accel_gate = 0.005;
  // deg: roll and pitch held to gravity (docs/imu.md, TiltHold). The accelerometers' gravity over the
  // first ten seconds is the reference; when a later ten seconds' turns further than this from it, the
  // attitude is turned back to this, a share each scan. Above what a consumer unit's bias fakes on the
  // simulated drives (0.55 deg at most; an industrial unit's 0.3 deg). 0 turns the hold off.
  double tilt_hold_deg = 1.0;
};

struct Config {
  SensorConfig sensor;
  GroundConfig ground;
  NormalConfig normals;
  BevConfig bev;
  RegistrationConfig registration;
  ModelConfig model;
  DeskewConfig deskew;
  MapConfig map;
  RuntimeConfig runtime;
  LocalizationConfig localization;
  MotionConfig motion;
  StartSearchConfig start_search;
  ImuConfig imu;
};

// A parameter that YAML files, ROS parameters and command lines all set by the same dotted key
// (`ground.max_slope_deg`). Choices (enums) travel as strings.
using ParameterValue = std::variant<bool, int, double, std::string, std::vector<double>>;

struct Parameter {
  std::string key;
  std::string description;
  std::vector<std::string> choices;  // non-empty for enumerations
  std::function<ParameterValue()> get;
  std::function<void(const ParameterValue&)> set;  // throws ConfigError on a wrong type or choice
};

class ConfigError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// The table of every parameter of `config`, bound to its fields.
std::vector<Parameter> parameters(Config& config);

// Throws ConfigError naming the first parameter whose value cannot work (e.g. a zero image width).
void validate(const Config& config);
void validate(const MapConfig& map);

// Converts a value read as text (command line, YAML scalar) to the parameter's type and sets it.
void setFromString(const Parameter& parameter, const std::string& text);
std::string toString(const ParameterValue& value);

}  // namespace elo
