#include "options.hpp"

#include <algorithm>
#include <cmath>
#include <sstream>

#include "command_line.hpp"
#include "elo/io/config_yaml.hpp"
#include "elo/drive_session.hpp"

namespace elo::tools {
namespace {

// "x y z yaw_deg" (commas allowed): the sensor's pose in the map at the first scan. A z of "nan" takes
// the height from the map's ground under x, y.
Eigen::Isometry3d parseInitialPose(std::string text) {
  for (char& c : text) {
    if (c == ',') c = ' ';
  }
  std::istringstream stream(text);
  std::vector<double> values;
  std::string item;
  while (stream >> item) values.push_back(parseNumber<double>("--initial-pose", item));
  if (values.size() != 4 || !std::isfinite(values[0]) || !std::isfinite(values[1]) || !std::isfinite(values[3])) {
    throw UsageError("--initial-pose expects \"x y z yaw_deg\", got '" + text + "'");
  }
  return poseFromXyzYaw(values);
}

}  // namespace

const char kEloRunUsage[] = R"(usage: elo_run --input DIR|BAG --output POSES [options]

Runs ELO odometry over DIR (KITTI layout: DIR/velodyne/*.bin with optional times.txt and calib.txt;
or a directory of .pcd / .bin scans) or over the sensor_msgs/PointCloud2 clouds of a bag (a ROS 1
DRIVE.bag, or a ROS 2 bag directory: metadata.yaml and *.db3) in header-stamp order, and writes one
KITTI pose line per scan (sensor frame, scan 0 at the origin). With DIR/calib.txt it also writes the
camera-frame trajectory the KITTI devkit scores. A scan that cannot be read (missing, truncated,
malformed file or message) or used is skipped and counted like a scan the odometry cannot use: its pose
line repeats the last pose, and the summary says how many and why. A run that fails part-way still
writes the poses of the scans before the failure.

options:
  --topic NAME         the bag's cloud topic (default: its only PointCloud2 topic)
  --imu-topic NAME     with imu.enabled, the bag's Imu topic, sensor_msgs/Imu in a ROS 1 bag or
                       sensor_msgs/msg/Imu in a ROS 2 bag (default: its only one; none: the LiDAR alone,
                       with a warning). A directory's IMU is its imu.txt (docs/imu.md)
  --config FILE        YAML overrides of the defaults (see config/*.yaml, --dump-config); given again,
                       each file over the ones before (a sensor's, then elo_sim's imu.yaml)
  --mode f2m|f2f       frame-to-model (default) or frame-to-frame
  --threads N          CPU threads (default: all)
  --backend cpu|cuda   compute backend (runtime.backend; default cpu)
  --set KEY=VALUE      override one parameter, e.g. --set ground.sensor_height=1.8 (repeatable)
  --frames N           process only the first N scans (of those --start, --stride and --reverse play)
  --start N            play the scans from scan N on, the first of them at the origin: a bag cut
                       mid-drive, or a node started on a moving car (default 0; not with --reverse);
                       the poses written are those of scans N, N+K, ... (K: --stride)
  --stride K           play every K-th scan from the first: a faster drive, or dropped frames
                       (default 1); score it against every K-th ground-truth pose
  --reverse            play the scans last to first, the route driven backwards (stamps mirrored
                       so time still advances, and each sweep: its per-point times, or the way a
                       sensor timed by azimuth turns); elo_eval --reverse compares it with a forward
                       run. Not with imu.enabled
  --timing CSV         per-frame stage times, iterations, deskew rounds, inlier counts and degeneracy
  --tum FILE           also write the trajectory in TUM format (stamp x y z qx qy qz qw; a bag's
                       stamps are its clouds' header stamps)
  --map FILE.pcd       write the drive's map (docs/map.md): binary PCD, x y z intensity normal_x
                       normal_y normal_z, one point per voxel, in the first scan's sensor frame; also
                       when the run fails part-way
  --map-voxel METERS   the map's voxel edge (map.voxel_size; default 0.2)
  --camera-output FILE camera-frame poses (default: POSES with _camera before the extension)
  --strict             stop at the first scan that cannot be read and exit 1 (after writing the
                       poses of the scans before it), instead of skipping it
  --no-prefetch        upload each scan to the GPU only when it is processed, as the node does, not
                       while the scan before it is (the poses are the same)
  --quiet              no progress bar
  --localize MAP.pcd   localize in a saved map (PCD: x y z [intensity] [normal_x normal_y normal_z], in
                       the map frame; normals estimated at load when absent): POSES are then the
                       sensor's poses in the map frame (docs/localization.md)
  --initial-pose "x y z yaw_deg"
                       with --localize: the sensor's pose in the map at the first scan, searched
                       around (localization.search_*); default the map's origin, as a map made by
                       elo_run --map of a drive that started where this one does
  --dump-config        print the effective configuration as YAML and exit
  --help
)";

Options parseArguments(int argc, char** argv) {
  Options options;
  Arguments arguments(argc, argv);
  while (arguments.next()) {
    if (arguments.is("--input")) {
      options.input = arguments.value();
    } else if (arguments.is("--topic")) {
      options.topic = arguments.value();
    } else if (arguments.is("--imu-topic")) {
      options.imu_topic = arguments.value();
    } else if (arguments.is("--output")) {
      options.output = arguments.value();
    } else if (arguments.is("--config")) {
      options.config_files.push_back(arguments.value());
    } else if (arguments.is("--mode")) {
      const std::string mode = arguments.value();
      if (mode != "f2m" && mode != "f2f") throw UsageError("--mode must be f2m or f2f, got '" + mode + "'");
      options.overrides.emplace_back("model.mode", mode == "f2m" ? "frame_to_model" : "frame_to_frame");
    } else if (arguments.is("--backend")) {
      options.overrides.emplace_back("runtime.backend", arguments.value());
    } else if (arguments.is("--threads")) {
      options.overrides.emplace_back("runtime.threads", std::to_string(arguments.number<int>()));
    } else if (arguments.is("--set")) {
      const std::string assignment = arguments.value();
      const size_t equals = assignment.find('=');
      if (equals == std::string::npos) throw UsageError("--set expects KEY=VALUE, got '" + assignment + "'");
      options.overrides.emplace_back(assignment.substr(0, equals), assignment.substr(equals + 1));
    } else if (arguments.is("--frames")) {
      options.max_frames = arguments.number<size_t>();
    } else if (arguments.is("--stride")) {
      options.stride = arguments.number<size_t>();
      if (options.stride == 0) throw UsageError("--stride must be at least 1");
    } else if (arguments.is("--start")) {
      options.start = arguments.number<size_t>();
    } else if (arguments.is("--reverse")) {
      options.reverse = true;
    } else if (arguments.is("--timing")) {
      options.timing_csv = arguments.value();
    } else if (arguments.is("--tum")) {
      options.tum_output = arguments.value();
    } else if (arguments.is("--map")) {
      options.map_output = arguments.value();
    } else if (arguments.is("--map-voxel")) {
      options.overrides.emplace_back("map.voxel_size", arguments.value());
    } else if (arguments.is("--camera-output")) {
      options.camera_output = arguments.value();
    } else if (arguments.is("--strict")) {
      options.strict = true;
    } else if (arguments.is("--no-prefetch")) {
      options.prefetch = false;
    } else if (arguments.is("--quiet")) {
      options.quiet = true;
    } else if (arguments.is("--localize")) {
      options.localize_map = arguments.value();
    } else if (arguments.is("--initial-pose")) {
      options.initial_pose = parseInitialPose(arguments.value());
    } else if (arguments.is("--dump-config")) {
      options.dump_config = true;
    } else {
      arguments.rejectFlag();
    }
  }
  if (!options.dump_config && (options.input.empty() || options.output.empty())) {
    throw UsageError("--input and --output are required");
  }
  // A reverse run from scan N would play N, N-1, ..., 0: the drive's start driven backwards, which no
  // recording holds; the reverse of a cut drive is --reverse over the cut itself.
  if (options.reverse && options.start > 0) throw UsageError("--start and --reverse cannot be combined");
  return options;
}

Config loadConfig(const Options& options) {
  elo::Config config;
  for (const std::string& file : options.config_files) elo::loadConfigYaml(file, config);
  std::vector<elo::Parameter> table = elo::parameters(config);
  for (const auto& [key, text] : options.overrides) {
    const auto parameter = std::find_if(table.begin(), table.end(), [&](const auto& p) { return p.key == key; });
    if (parameter == table.end()) throw elo::ConfigError("unknown parameter '" + key + "'");
    elo::setFromString(*parameter, text);
  }
  elo::validate(config);
  if (options.reverse) {
    // The IMU's samples would have to be played backwards too, their rates and forces mirrored.
    if (config.imu.enabled) throw UsageError("--reverse cannot take an IMU: run it with imu.enabled false");
    elo::reverseSweepDirection(config.sensor);
  }
  return config;
}

std::string cameraOutputPath(const Options& options) {
  if (!options.camera_output.empty()) return options.camera_output;
  const size_t dot = options.output.rfind('.');
  const size_t slash = options.output.rfind('/');
  if (dot == std::string::npos || (slash != std::string::npos && dot < slash)) return options.output + "_camera";
  return options.output.substr(0, dot) + "_camera" + options.output.substr(dot);
}

std::vector<PlayedScan> playedScans(const elo::ScanSource& source, const Options& options) {
  if (options.start > 0 && options.start >= source.size()) {
    throw UsageError("--start " + std::to_string(options.start) + ": the input has " + std::to_string(source.size()) +
                     " scans");
  }
  return elo::playOrder(source, options.stride, options.reverse, options.max_frames, options.start);
}

}  // namespace elo::tools
