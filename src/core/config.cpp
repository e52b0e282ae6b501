#include "elo/config.hpp"

#include <algorithm>
#include <cmath>
#include <sstream>
#include <type_traits>
#include <utility>

namespace elo {

std::vector<double> SensorConfig::hdl64BeamElevations() {
  std::vector<double> elevations;
  constexpr int kBeamsPerBlock = 32;
  const auto add_block = [&](double top, double bottom) {
    for (int i = 0; i < kBeamsPerBlock; ++i) {
      elevations.push_back(top + (bottom - top) * i / (kBeamsPerBlock - 1));
    }
  };
  add_block(2.0, -8.33);
  add_block(-8.83, -24.33);
  return elevations;
}

namespace {

template <typename T>
const char* typeName() {
  if constexpr (std::is_same_v<T, bool>) return "a boolean";
  if constexpr (std::is_same_v<T, int>) return "an integer";
  if constexpr (std::is_same_v<T, double>) return "a number";
  if constexpr (std::is_same_v<T, std::string>) return "a string";
  if constexpr (std::is_same_v<T, std::vector<double>>) return "a list of numbers";
}

// Reads `value` as a T, widening int to double, or throws naming the parameter.
template <typename T>
T convert(const std::string& key, const ParameterValue& value) {
  if (const T* exact = std::get_if<T>(&value)) return *exact;
  if constexpr (std::is_same_v<T, double>) {
    if (const int* integer = std::get_if<int>(&value)) return *integer;
  }
  if constexpr (std::is_same_v<T, std::vector<double>>) {
    if (const double* single = std::get_if<double>(&value)) return {*single};
  }
  throw ConfigError("parameter '" + key + "' expects " + typeName<T>() + ", got '" + toString(value) + "'");
}

template <typename T>
Parameter bindField(std::string key, T& field, std::string description) {
  Parameter parameter;
  parameter.key = key;
  parameter.description = std::move(description);
  parameter.get = [&field] { return ParameterValue(field); };
  parameter.set = [&field, key](const ParameterValue& value) { field = convert<T>(key, value); };
  return parameter;
}

template <typename Enum>
Parameter bindChoice(std::string key, Enum& field, std::vector<std::pair<Enum, std::string>> names,
                     std::string description) {
  Parameter parameter;
  parameter.key = key;
  parameter.description = std::move(description);
  for (const auto& name : names) parameter.choices.push_back(name.second);
  parameter.get = [&field, names] {
    for (const auto& [value, name] : names) {
      if (value == field) return ParameterValue(name);
    }
    return ParameterValue(std::string("?"));
  };
  parameter.set = [&field, names, key](const ParameterValue& value) {
    const std::string text = convert<std::string>(key, value);
    for (const auto& [choice, name] : names) {
      if (name == text) {
        field = choice;
        return;
      }
    }
    std::string known;
    for (const auto& name : names) known += (known.empty() ? "" : "|") + name.second;
    throw ConfigError("parameter '" + key + "' must be one of " + known + ", got '" + text + "'");
  };
  return parameter;
}

void require(bool condition, const std::string& key, const std::string& requirement) {
  if (!condition) throw ConfigError("parameter '" + key + "' " + requirement);
}

bool isOdd(int value) { return value > 0 && value % 2 == 1; }

}  // namespace

std::vector<Parameter> parameters(Config& c) {
  SensorConfig& s = c.sensor;
  GroundConfig& g = c.ground;
  NormalConfig& n = c.normals;
  BevConfig& b = c.bev;
  RegistrationConfig& r = c.registration;
  ModelConfig& m = c.model;
  return {
      bindField("sensor.name", s.name, "sensor model name (informative)"),
      bindField("sensor.image_width", s.image_width, "w_S: columns of the spherical range image (Sec. III-B.1)"),
      bindField("sensor.image_height", s.image_height, "h_S: rows of the spherical range image (Sec. III-B.1)"),
      bindField("sensor.fov_up_deg", s.fov_up_deg, "f_up: elevation of the image top, deg (Eq. 4)"),
      bindField("sensor.fov_down_deg", s.fov_down_deg, "f_down: elevation of the image bottom, deg, negative (Eq. 4)"),
      bindField("sensor.min_range", s.min_range, "returns closer than this (m) are dropped"),
      bindField("sensor.max_range", s.max_range, "returns farther than this (m) are dropped"),
      bindField("sensor.elevation_correction_deg", s.elevation_correction_deg,
           "raise every point's elevation by this angle; 0.195 for KITTI (Sec. IV-A)"),
      bindField("sensor.beam_elevations_deg", s.beam_elevations_deg,
           "nominal beam elevations top to bottom (ring_zero table: in ring order), deg; empty = beam_count "
           "beams spread evenly"),
      bindField("sensor.beam_count", s.beam_count, "number of beams"),
      bindChoice("sensor.ring_zero", s.ring_zero,
                 {{RingZero::bottom, "bottom"}, {RingZero::top, "top"}, {RingZero::table, "table"}},
                 "the beam a cloud's ring 0 is: bottom (velodyne_pointcloud counts up from the lowest beam), top "
                 "(ouster_ros counts down from the highest) or table (ring k is beam_elevations_deg's entry k)"),
      bindField("sensor.azimuth_steps", s.azimuth_steps, "firings per revolution (simulator)"),
      bindField("sensor.rotation_rate_hz", s.rotation_rate_hz,
                "revolutions per second (simulator, azimuth times, window of per-point times)"),
      bindField("sensor.clockwise", s.clockwise, "the sensor turns clockwise seen from above (azimuth times, simulator)"),
      bindField("sensor.sweep_start_azimuth_deg", s.sweep_start_azimuth_deg,
                "azimuth where each sweep starts, deg counter-clockwise from x; 180 = straight behind (azimuth "
                "times, simulator)"),
      bindField("sensor.range_noise_stddev", s.range_noise_stddev, "range noise, m (simulator)"),
      bindField("ground.sensor_height", g.sensor_height, "h_g: sensor height above the road, m (Sec. III-C.1)"),
      bindField("ground.band_above", g.band_above, "delta_h1: ground band above the road height, m (Sec. III-C.1)"),
      bindField("ground.band_below", g.band_below, "delta_h2: ground band below the road height, m (Sec. III-C.1)"),
      bindField("ground.max_slope_deg", g.max_slope_deg, "delta_theta: slope limit between column neighbours, deg (Eq. 13)"),
      bindField("ground.rise_tolerance", g.rise_tolerance,
                "rise allowed between column neighbours on top of delta_theta's, m (range noise)"),
      bindField("ground.min_range", g.min_range,
                "within it the ground band is ground and out of both terms (the near road), m; 0: off"),
      bindChoice("normals.method", n.method,
                 {{NormalMethod::range_adaptive, "range_adaptive"},
                  {NormalMethod::eigen, "eigen"},
                  {NormalMethod::cross_product, "cross_product"}},
                 "normal estimator (Table III); eigen = fixed largest window without outlier tests"),
      bindField("normals.search_size", n.search_size, "delta: metric window size, m (Eq. 12)"),
      bindField("normals.min_window_width", n.min_window_width, "l_x^min, pixels, odd (Eq. 12)"),
      bindField("normals.max_window_width", n.max_window_width, "l_x^max, pixels, odd (Eq. 12)"),
      bindField("normals.min_window_height", n.min_window_height, "l_y^min, pixels, odd (Eq. 12)"),
      bindField("normals.max_window_height", n.max_window_height, "l_y^max, pixels, odd (Eq. 12)"),
      bindField("normals.outlier_distance", n.outlier_distance, "sigma_r: neighbour distance test, m (Sec. III-B.4)"),
      bindField("normals.plane_distance", n.plane_distance, "sigma_z: point-to-plane test at refit, m (Sec. III-B.4)"),
      bindField("normals.min_neighbours", n.min_neighbours, "fewest inlier points for a normal"),
      bindField("normals.max_curvature", n.max_curvature, "planar point selection by curvature (Eq. 11)"),
      bindField("bev.cell_size", b.cell_size, "s: BEV cell size, m (Eq. 14)"),
      bindField("bev.half_length", b.half_length, "w_B: BEV half extent along x, m (Eq. 14)"),
      bindField("bev.half_width", b.half_width, "h_B: BEV half extent along y, m (Eq. 14)"),
      bindField("bev.normal_neighbours", b.normal_neighbours, "model points fitted for a ground normal (Sec. III-C.2)"),
      bindField("bev.normal_patch_radius", b.normal_patch_radius, "cells searched for them around the association"),
      bindChoice("registration.terms", r.terms,
                 {{CostTerms::fused, "fused"},
                  {CostTerms::spherical_all, "spherical_all"},
                  {CostTerms::spherical_nonground, "spherical_nonground"},
                  {CostTerms::bev_ground, "bev_ground"}},
                 "cost terms (Table II): fused SRI+BEV, or one projection alone"),
      bindField("registration.nonground_weight", r.nonground_weight, "w1 of w = w1*w2 (Eq. 1)"),
      bindField("registration.max_iterations", r.max_iterations, "Gauss-Newton iteration limit"),
      bindField("registration.converged_translation", r.converged_translation, "stop when the update moves less, m"),
      bindField("registration.converged_rotation", r.converged_rotation, "... and turns less, rad"),
      bindField("registration.max_correspondence_distance", r.max_correspondence_distance,
           "gate on the distance between a moved scan point and its model point, m"),
      bindField("registration.max_normal_angle_deg", r.max_normal_angle_deg, "gate on the scan/model normal angle, deg"),
      bindField("registration.association_radius", r.association_radius,
           "pixels searched around the projective association"),
      bindField("registration.robust_kernel_scale", r.robust_kernel_scale,
                "Geman-McClure scale for point-to-plane residuals, m; 0 = plain least squares"),
      bindField("registration.near_weight_range", r.near_weight_range,
                "a non-ground correspondence nearer than this weighs its range over it, m; 0 = all alike"),
      bindField("registration.degeneracy_threshold", r.degeneracy_threshold,
                "share of the constraint below which a direction of motion is degenerate and keeps the motion "
                "prior (scaled Hessian eigenvalue); 0 = off"),
      bindChoice("model.mode", m.mode,
                 {{RegistrationMode::frame_to_model, "frame_to_model"},
                  {RegistrationMode::frame_to_frame, "frame_to_frame"}},
                 "register against the fused model or the previous scan (Sec. III-D)"),
      bindField("model.time_window", m.time_window, "tau_w: model points older than this are dropped, s (Sec. III-D)"),
      bindField("model.same_surface_distance", m.same_surface_distance,
                "a closer point wins a model pixel or BEV cell only when closer by more than this, m; within it "
                "the oldest stays; 0 = the paper's literal closer-wins"),
      bindChoice("model.motion_prior", m.motion_prior,
                 {{MotionPrior::constant_acceleration, "constant_acceleration"},
                  {MotionPrior::constant_velocity, "constant_velocity"},
                  {MotionPrior::none, "none"}},
                 "initial guess of the registration (Sec. III-A)"),
      bindChoice("deskew.time_source", c.deskew.time_source,
                 {{TimeSource::none, "none"}, {TimeSource::field, "field"}, {TimeSource::azimuth, "azimuth"}},
                 "per-point firing times for motion compensation: none (instantaneous scans), field (the cloud's "
                 "times, relative to its stamp), azimuth (from each point's azimuth; reference mid-sweep)"),
      bindField("deskew.rounds", c.deskew.rounds,
                "rounds of deskewing again under the motion estimated so far, one after each of the registration's first Gauss-Newton steps"),
      bindField("map.voxel_size", c.map.voxel_size, "edge of a voxel of the drive's map, m (docs/map.md)"),
      bindField("map.min_observations", c.map.min_observations,
                "scans the drive's map took that must see a non-ground voxel for it to be written (moving objects)"),
      bindField("map.scan_stride", c.map.scan_stride,
                "the drive's map takes every n-th registered scan; 1 = every scan (docs/map.md)"),
      bindChoice("runtime.backend", c.runtime.backend,
                 {{BackendKind::cpu, "cpu"}, {BackendKind::cuda, "cuda"}}, "compute backend"),
      bindField("runtime.backend_fallback", c.runtime.backend_fallback,
                "with backend cuda and no usable GPU, run on the CPU backend with a warning instead of failing"),
      bindField("runtime.threads", c.runtime.threads, "CPU threads, 0 = all"),
      bindField("localization.render_range", c.localization.render_range,
                "m around the sensor whose map points are rendered for each map match"),
      bindField("localization.tile_size", c.localization.tile_size, "m: side of the map index's tiles"),
      bindField("localization.splat_radius", c.localization.splat_radius,
                "m: radius of the disc each map point covers in the rendered range image"),
      bindField("localization.normal_radius", c.localization.normal_radius,
                "m: neighbourhood fitted for a map point's normal when the map file has none"),
      bindField("localization.min_inlier_share", c.localization.min_inlier_share,
                "share of the scan's features that must find a map correspondence for a match to be accepted"),
      bindField("localization.max_rms", c.localization.max_rms,
                "m: point-to-plane RMS of the correspondences above which a match is refused"),
      bindField("localization.max_correction", c.localization.max_correction,
                "m: a tracked match moving the pose further than this from the prediction is refused"),
      bindField("localization.lost_after", c.localization.lost_after,
                "refused or failed map matches in a row after which the vehicle is lost"),
      bindField("localization.search_radius", c.localization.search_radius,
                "m: the initial-pose search tries positions within this distance of the hint"),
      bindField("localization.search_step", c.localization.search_step, "m between the search's positions"),
      bindField("localization.search_yaw_deg", c.localization.search_yaw_deg,
                "deg: the search tries yaws within this angle either side of the hint's"),
      bindField("localization.search_yaw_step_deg", c.localization.search_yaw_step_deg, "deg between the search's yaws"),
      bindField("localization.search_refined", c.localization.search_refined,
                "best-scored search candidates registered to convergence"),
      bindField("localization.search_margin", c.localization.search_margin,
                "inlier share by which a search's winner must beat a candidate that converged elsewhere"),
      bindField("motion.max_speed", c.motion.max_speed,
                "m/s: a registration moving the sensor faster is refused; the start search's reach along x"),
      bindField("motion.max_turn_rate_deg", c.motion.max_turn_rate_deg, "deg/s: a registration turning faster is refused"),
      bindField("motion.max_acceleration", c.motion.max_acceleration,
                "m/s^2: a registration changing the velocity more than this over the scan interval is refused"),
      bindField("motion.stamp_jitter", c.motion.stamp_jitter,
                "s: error of a scan's stamp, whose effect on the velocity max_acceleration tolerates"),
      bindField("motion.min_inlier_share_of_recent", c.motion.min_inlier_share_of_recent,
                "a registration with fewer inliers than this share of the recent ones' median is refused"),
      bindField("motion.restart_after", c.motion.restart_after,
                "refused registrations in a row after which the model restarts from the scan at hand"),
      bindField("start_search.enabled", c.start_search.enabled,
                "search the motion of a scan registered with none known (a start on a moving vehicle)"),
      bindField("start_search.step", c.start_search.step, "m between the start search's candidates along x"),
      bindField("start_search.max_yaw_rate_deg", c.start_search.max_yaw_rate_deg,
                "deg/s: the start search's candidates reach this times the scan interval in yaw, either way"),
      bindField("start_search.yaw_step_deg", c.start_search.yaw_step_deg, "deg between the start search's yaws"),
      bindField("start_search.margin", c.start_search.margin,
                "fit score within which a candidate that ended elsewhere makes a start ambiguous"),
      bindField("start_search.after_gap_periods", c.start_search.after_gap_periods,
                "usual scan intervals after which a scan follows a gap: its motion is searched"),
      bindField("imu.enabled", c.imu.enabled, "turn the motion prior and the deskew by the IMU's gyro (docs/imu.md)"),
      bindField("imu.position", c.imu.position, "m: the IMU's origin in the LiDAR frame, [x, y, z]"),
      bindField("imu.rotation_deg", c.imu.rotation_deg,
                "deg: the IMU's axes in the LiDAR frame, [roll, pitch, yaw] about the LiDAR's x, y, z"),
      bindField("imu.time_offset", c.imu.time_offset, "s added to the IMU's stamps to put them on the scans' clock"),
      bindField("imu.min_rate_hz", c.imu.min_rate_hz,
                "Hz: no gyro integration across a gap of more than two periods at this rate"),
      bindField("imu.gyro_limit_dps", c.imu.gyro_limit_dps, "deg/s: a sample at or beyond this on an axis is saturated, dropped"),
      bindField("imu.gyro_bias", c.imu.gyro_bias, "rad/s: the gyro's bias in the IMU's axes at the start, [x, y, z]"),
      bindField("imu.bias_time_constant", c.imu.bias_time_constant,
                "s: the gyro's bias estimated online against the registered rotations over about this long; 0: fixed"),
      bindField("imu.accelerometer", c.imu.accelerometer,
                "the translation of the motion prior from the velocity and the integrated specific force"),
      bindField("imu.accel_limit", c.imu.accel_limit,
                "m/s^2: a specific force at or beyond this on an axis is saturated, dropped"),
      bindField("imu.accel_bias", c.imu.accel_bias,
                "m/s^2: the accelerometers' bias in the IMU's axes at the start, [x, y, z]"),
      bindField("imu.accel_bias_time_constant", c.imu.accel_bias_time_constant,
                "s: the accelerometers' bias estimated online against the registered translations; 0: fixed"),
      bindField("imu.accel_gate", c.imu.accel_gate,
                "m: an interval's specific force not taken when its translation missed the registered one by "
                "more than the LiDAR-only prior's did, plus this"),
      bindField("imu.tilt_hold_deg", c.imu.tilt_hold_deg,
                "deg: roll and pitch turned back towards gravity when the accelerometers' gravity is further than "
                "this from where it was once known; 0: off"),
  };
}

void validate(const MapConfig& map) {
  require(map.voxel_size >= 0.01 && map.voxel_size <= 10.0, "map.voxel_size", "must lie in [0.01, 10] m");
  require(map.min_observations >= 1 && map.min_observations <= 1000, "map.min_observations", "must lie in [1, 1000]");
  require(map.scan_stride >= 1 && map.scan_stride <= 100, "map.scan_stride", "must lie in [1, 100]");
}

namespace {

void validateLocalization(const LocalizationConfig& l) {
  require(l.render_range > 0.0, "localization.render_range", "must be positive");
  require(l.tile_size > 0.0, "localization.tile_size", "must be positive");
  require(l.splat_radius >= 0.0, "localization.splat_radius", "must not be negative");
  require(l.normal_radius > 0.0, "localization.normal_radius", "must be positive");
  require(l.min_inlier_share >= 0.0 && l.min_inlier_share <= 1.0, "localization.min_inlier_share", "must lie in [0, 1]");
  require(l.max_rms > 0.0, "localization.max_rms", "must be positive");
  require(l.max_correction > 0.0, "localization.max_correction", "must be positive");
  require(l.lost_after >= 1, "localization.lost_after", "must be at least 1");
  require(l.search_radius >= 0.0, "localization.search_radius", "must not be negative");
  require(l.search_step > 0.0, "localization.search_step", "must be positive");
  require(l.search_yaw_deg >= 0.0 && l.search_yaw_deg <= 180.0, "localization.search_yaw_deg", "must lie in [0, 180]");
  require(l.search_yaw_step_deg > 0.0, "localization.search_yaw_step_deg", "must be positive");
  require(l.search_refined >= 1, "localization.search_refined", "must be at least 1");
  require(l.search_margin >= 0.0, "localization.search_margin", "must not be negative");
}

}  // namespace

void validate(const Config& c) {
  const SensorConfig& s = c.sensor;
  require(s.image_width > 0, "sensor.image_width", "must be positive");
  require(s.image_height > 0, "sensor.image_height", "must be positive");
  require(s.fov_up_deg > s.fov_down_deg, "sensor.fov_up_deg", "must be above sensor.fov_down_deg");
  require(s.fov_up_deg <= 90.0 && s.fov_down_deg >= -90.0, "sensor.fov_up_deg", "and fov_down_deg must lie in [-90, 90]");
  require(s.min_range >= 0.0, "sensor.min_range", "must not be negative");
  require(s.max_range > s.min_range, "sensor.max_range", "must exceed sensor.min_range");
  require(std::abs(s.elevation_correction_deg) < 5.0, "sensor.elevation_correction_deg", "must be under 5 deg");
  require(s.beam_count > 0, "sensor.beam_count", "must be positive");
  require(s.beam_elevations_deg.empty() || static_cast<int>(s.beam_elevations_deg.size()) == s.beam_count,
          "sensor.beam_elevations_deg", "must list sensor.beam_count elevations (or none)");
  // Rings counted from the top or the bottom name the right beams only if the table runs top to bottom.
  require(s.ring_zero == RingZero::table ||
              std::is_sorted(s.beam_elevations_deg.rbegin(), s.beam_elevations_deg.rend()),
          "sensor.beam_elevations_deg", "must run from the top beam down (or set sensor.ring_zero: table)");
  require(s.ring_zero != RingZero::table || !s.beam_elevations_deg.empty(), "sensor.ring_zero",
          "table needs sensor.beam_elevations_deg in the driver's ring order");
  require(s.azimuth_steps > 0, "sensor.azimuth_steps", "must be positive");
  require(s.rotation_rate_hz > 0.0, "sensor.rotation_rate_hz", "must be positive");
  require(s.range_noise_stddev >= 0.0, "sensor.range_noise_stddev", "must not be negative");

  const GroundConfig& g = c.ground;
  require(g.sensor_height > 0.0, "ground.sensor_height", "must be positive");
  require(g.band_above > 0.0, "ground.band_above", "must be positive");
  require(g.band_below > 0.0, "ground.band_below", "must be positive");
  require(g.max_slope_deg > 0.0 && g.max_slope_deg < 90.0, "ground.max_slope_deg", "must lie in (0, 90)");
  require(g.rise_tolerance >= 0.0, "ground.rise_tolerance", "must not be negative");
  require(g.min_range >= 0.0, "ground.min_range", "must not be negative");

  const NormalConfig& n = c.normals;
  require(n.search_size > 0.0, "normals.search_size", "must be positive");
  require(isOdd(n.min_window_width), "normals.min_window_width", "must be a positive odd number");
  require(isOdd(n.max_window_width) && n.max_window_width >= n.min_window_width, "normals.max_window_width",
          "must be odd and at least normals.min_window_width");
  require(isOdd(n.min_window_height), "normals.min_window_height", "must be a positive odd number");
  require(isOdd(n.max_window_height) && n.max_window_height >= n.min_window_height, "normals.max_window_height",
          "must be odd and at least normals.min_window_height");
  require(n.outlier_distance > 0.0, "normals.outlier_distance", "must be positive");
  require(n.plane_distance > 0.0, "normals.plane_distance", "must be positive");
  require(n.min_neighbours >= 3, "normals.min_neighbours", "must be at least 3 (a plane needs three points)");
  require(n.max_curvature > 0.0 && n.max_curvature <= 1.0 / 3.0, "normals.max_curvature", "must lie in (0, 1/3]");

  const BevConfig& b = c.bev;
  require(b.cell_size > 0.0, "bev.cell_size", "must be positive");
  require(b.half_length > 0.0, "bev.half_length", "must be positive");
  require(b.half_width > 0.0, "bev.half_width", "must be positive");
  const double cells = (2.0 * b.half_length / b.cell_size) * (2.0 * b.half_width / b.cell_size);
  require(cells <= 1e8, "bev.cell_size", "gives more than 1e8 BEV cells: enlarge it or shrink the extents");
  require(b.normal_neighbours >= 3 && b.normal_neighbours <= 32, "bev.normal_neighbours", "must lie in [3, 32]");
  require(b.normal_patch_radius >= 1, "bev.normal_patch_radius", "must be at least 1");

  const RegistrationConfig& r = c.registration;
  require(r.nonground_weight >= 0.0 && r.nonground_weight <= 1.0, "registration.nonground_weight", "must lie in [0, 1]");
  require(r.max_iterations >= 1, "registration.max_iterations", "must be at least 1");
  require(r.converged_translation > 0.0, "registration.converged_translation", "must be positive");
  require(r.converged_rotation > 0.0, "registration.converged_rotation", "must be positive");
  require(r.max_correspondence_distance > 0.0, "registration.max_correspondence_distance", "must be positive");
  require(r.max_normal_angle_deg > 0.0 && r.max_normal_angle_deg <= 180.0, "registration.max_normal_angle_deg",
          "must lie in (0, 180]");
  require(r.association_radius >= 0 && r.association_radius <= s.image_width / 2, "registration.association_radius",
          "must lie in [0, sensor.image_width / 2]");
  require(r.robust_kernel_scale >= 0.0, "registration.robust_kernel_scale", "must not be negative");
  require(r.near_weight_range >= 0.0, "registration.near_weight_range", "must not be negative");
  // The six scaled eigenvalues sum to 2, so the smallest is at most 1/3: a threshold that high would find
  // every scan degenerate.
  require(r.degeneracy_threshold >= 0.0 && r.degeneracy_threshold < 1.0 / 3.0, "registration.degeneracy_threshold",
          "must lie in [0, 1/3)");

  require(c.model.time_window > 0.0, "model.time_window", "must be positive");
  require(c.model.same_surface_distance >= 0.0, "model.same_surface_distance", "must not be negative");
  require(std::isfinite(s.sweep_start_azimuth_deg), "sensor.sweep_start_azimuth_deg", "must be finite");
  require(c.deskew.rounds >= 0 && c.deskew.rounds <= 5, "deskew.rounds", "must lie in [0, 5]");
  validate(c.map);
  require(c.runtime.threads >= 0, "runtime.threads", "must not be negative");
  validateLocalization(c.localization);
  const MotionConfig& motion = c.motion;
  require(motion.max_speed > 0.0, "motion.max_speed", "must be positive");
  require(motion.max_turn_rate_deg > 0.0, "motion.max_turn_rate_deg", "must be positive");
  require(motion.max_acceleration > 0.0, "motion.max_acceleration", "must be positive");
  require(motion.stamp_jitter >= 0.0, "motion.stamp_jitter", "must not be negative");
  require(motion.min_inlier_share_of_recent >= 0.0 && motion.min_inlier_share_of_recent < 1.0,
          "motion.min_inlier_share_of_recent", "must lie in [0, 1)");
  require(motion.restart_after >= 1, "motion.restart_after", "must be at least 1");
  const StartSearchConfig& start = c.start_search;
  require(start.step > 0.0, "start_search.step", "must be positive");
  require(start.max_yaw_rate_deg >= 0.0, "start_search.max_yaw_rate_deg", "must not be negative");
  require(start.yaw_step_deg > 0.0, "start_search.yaw_step_deg", "must be positive");
  require(start.margin >= 0.0, "start_search.margin", "must not be negative");
  require(start.after_gap_periods > 1.0, "start_search.after_gap_periods", "must exceed one scan period");
  const ImuConfig& imu = c.imu;
  require(imu.position.size() == 3, "imu.position", "must list 3 numbers: x, y, z");
  require(imu.rotation_deg.size() == 3, "imu.rotation_deg", "must list 3 numbers: roll, pitch, yaw");
  require(imu.gyro_bias.size() == 3, "imu.gyro_bias", "must list 3 numbers: x, y, z");
  require(imu.min_rate_hz > 0.0, "imu.min_rate_hz", "must be positive");
  require(imu.gyro_limit_dps > 0.0, "imu.gyro_limit_dps", "must be positive");
  require(imu.bias_time_constant >= 0.0, "imu.bias_time_constant", "must not be negative");
  require(imu.accel_limit > 0.0, "imu.accel_limit", "must be positive");
  require(imu.accel_bias.size() == 3, "imu.accel_bias", "must list 3 numbers: x, y, z");
  require(imu.accel_bias_time_constant >= 0.0, "imu.accel_bias_time_constant", "must not be negative");
  require(imu.accel_gate >= 0.0, "imu.accel_gate", "must not be negative");
  require(imu.tilt_hold_deg >= 0.0 && imu.tilt_hold_deg < 90.0, "imu.tilt_hold_deg", "must be in [0, 90)");
}

void setFromString(const Parameter& parameter, const std::string& text) {
  const ParameterValue current = parameter.get();
  std::istringstream stream(text);
  ParameterValue value;
  const auto fail = [&] {
    throw ConfigError("parameter '" + parameter.key + "' cannot be set from '" + text + "'");
  };
  if (std::holds_alternative<bool>(current)) {
    if (text == "true" || text == "1") value = true;
    else if (text == "false" || text == "0") value = false;
    else fail();
  } else if (std::holds_alternative<int>(current)) {
    int number = 0;
    if (!(stream >> number) || !stream.eof()) fail();
    value = number;
  } else if (std::holds_alternative<double>(current)) {
    double number = 0.0;
    if (!(stream >> number) || !stream.eof()) fail();
    value = number;
  } else if (std::holds_alternative<std::vector<double>>(current)) {
    std::vector<double> numbers;
    std::string item;
    while (std::getline(stream, item, ',')) {
      std::istringstream item_stream(item);
      double number = 0.0;
      if (!(item_stream >> number)) fail();
      numbers.push_back(number);
    }
    value = numbers;
  } else {
    value = text;
  }
  parameter.set(value);
}

std::string toString(const ParameterValue& value) {
  std::ostringstream out;
  out.precision(10);
  std::visit(
      [&out](const auto& v) {
        using T = std::decay_t<decltype(v)>;
        if constexpr (std::is_same_v<T, bool>) {
          out << (v ? "true" : "false");
        } else if constexpr (std::is_same_v<T, std::vector<double>>) {
          out << '[';
          for (size_t i = 0; i < v.size(); ++i) out << (i ? ", " : "") << v[i];
          out << ']';
        } else {
          out << v;
        }
      },
      value);
  return out.str();
}

}  // namespace elo
