// elo_sim: simulates a spinning LiDAR driving through a procedural world and writes a KITTI-layout
// sequence with exact ground truth. See --help.
#include <tbb/task_arena.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <exception>
#include <fstream>
#include <iostream>
#include <map>
#include <optional>
#include <string>

#include "elo/io/config_yaml.hpp"
#include "elo/io/imu_file.hpp"
#include "elo/io/kitti.hpp"
#include "elo/sim/imu.hpp"
#include "elo/sim/sensors.hpp"
#include "elo/sim/sequence_writer.hpp"
#include "elo/sim/simulation.hpp"
#include "command_line.hpp"
#include "sequence_bag.hpp"

namespace {

using elo::sim::SimulationSpec;

constexpr int kUsageError = 2;

std::string joined(const std::vector<std::string>& names) {
  std::string text;
  for (const std::string& name : names) text += (text.empty() ? "" : "|") + name;
  return text;
}

std::string usage() {
  return "Usage: elo_sim --world " + joined(elo::sim::worldNames()) + "\n"
         "               (--trajectory " + joined(elo::sim::trajectoryNames()) + " | --poses FILE)\n"
         "               --frames N --output DIR [--bag FILE] [options]\n"
         "\n"
         "Simulates a spinning LiDAR in a seeded procedural world and writes a sequence: the scans,\n"
         "DIR/poses.txt (ground truth in the sensor frame at each scan's stamp, scan 0 = identity),\n"
         "DIR/times.txt (the stamps) and DIR/calib.txt (KITTI 00's Tr).\n"
         "\n"
         "  --world NAME         kind of world: urban street canyon, highway, country road, parking lot,\n"
         "                       tunnel (2 km of featureless tube, 100 m after the start), indoor (a\n"
         "                       hall's corridors under a ceiling, walls 4 m either side, doorways, crates)\n"
         "  --trajectory NAME    procedural drive at the world's speed (urban 10 m/s, highway 25 m/s,\n"
         "                       country 18 m/s, parking 5 m/s, tunnel 16 m/s, indoor 6 m/s);\n"
         "                       hard-driving: braking at 0.8 g to a stop every 100 m, corners of 7-12 m\n"
         "                       radius at 5 m/s^2 (fast turns at low speed), 3 m/s^2 of acceleration\n"
         "  --poses FILE         drive through KITTI camera-frame ground-truth poses (converted to the\n"
         "                       LiDAR frame with KITTI 00's Tr; one pose per frame at 10 Hz)\n"
         "  --frames N           scans to simulate (with --poses: default all the poses)\n"
         "  --output DIR         where the sequence is written\n"
         "  --format bin|pcd     bin: KITTI's layout, DIR/velodyne/%06d.bin (x y z intensity; default);\n"
         "                       pcd: DIR/%06d.pcd (x y z intensity ring, and time as in the bag)\n"
         "  --bag FILE           also write the sequence as a ROS bag: sensor_msgs/PointCloud2 on /points\n"
         "                       (x y z intensity ring, and time with --time-convention field; frame\n"
         "                       velodyne, stamped as the scans +1 s), ground truth on /ground_truth and /tf\n"
         "                       (as kitti_to_bag --poses-frame lidar)\n"
         "  --sensor NAME        " + joined(elo::sim::sensorNames()) + " (default hdl64)\n"
         "  --seed S             seed of the world, the noise and the unit's calibration errors (default 1):\n"
         "                       same seed, same scans\n"
         "  --config FILE        YAML parameters applied over the sensor's (e.g. sensor.max_range)\n"
         "  --noise M            range noise standard deviation in metres (default: the sensor's, 0.02)\n"
         "  --dropout P          probability that a return is lost (default 0.01)\n"
         "  --deskewed 0|1       1: each scan taken at one instant, its stamp, and no per-point times\n"
         "                       (default); 0: the sensor moves during the sweep (0.1 s at 10 Hz), each\n"
         "                       point measured from where the sensor is when it fires\n"
         "  --time-convention field|azimuth\n"
         "                       with --deskewed 0, how the scans tell each point's time (the head turns\n"
         "                       clockwise seen from above, from straight behind, as KITTI's HDL-64E):\n"
         "                       field (default): a per-point `time` in the bag and PCD scans, in s from\n"
         "                       the stamp, which is the sweep's start; the ground truth is at the stamp.\n"
         "                       azimuth: no per-point times (KITTI .bin); a point's time is its sweep\n"
         "                       fraction 0.5 (1 - atan2(y, x) / pi); stamp and ground truth at mid-sweep\n"
         "  --moving-cars N      cars driving along the road (default 0)\n"
         "  --foliage-depth M    mean depth in metres that beams reach into leaves before echoing\n"
         "                       (default 0: solid crowns)\n"
         "  --mixed-pixels P     chance that a return at a depth edge comes from between the two\n"
         "                       surfaces (default 0)\n"
         "  --beam-range-bias M  standard deviation in metres of each laser's constant range offset\n"
         "                       (default 0: a perfectly calibrated unit)\n"
         "  --beam-elevation-error DEG\n"
         "                       standard deviation in degrees of each laser's constant elevation error\n"
         "                       (default 0); points are still reported along the nominal elevations\n"
         "  --range-offset M     every laser reads every range M metres long (negative: short; within\n"
         "                       [-1, 1]), on top of its own --beam-range-bias (default 0)\n"
         "  --lower-block-rise M\n"
         "                       the lasers of the lower half of the field (the HDL-64E's lower block)\n"
         "                       fire from M metres below where the points say, so that the road they\n"
         "                       reach near the sensor reads M higher (default 0; KITTI's HDL-64E reads\n"
         "                       it 0.02-0.04 higher)\n"
         "  --mirror 0|1         1: the drive in the world's mirror image (y -> -y; the sensor turns the\n"
         "                       other way), left turns made right ones (default 0); not with\n"
         "                       --time-convention azimuth\n"
         "  --gait " + joined(elo::sim::gaitNames()) + "\n"
         "                       how the sensor moves about the path (elo/sim/gait.hpp): walk, carried by\n"
         "                       hand (swung +-30 deg at 1 Hz, rocked +-10 deg, bobbing 4 cm at 1.8 steps\n"
         "                       a second); trot, on a legged robot (jolts of 3 cm and 4 deg at 3 footfalls\n"
         "                       a second); default none (a vehicle)\n"
         "  --imu " + joined(elo::sim::imuGradeNames()) + "\n"
         "                       also write DIR/imu.txt, the samples of an IMU of that grade bolted to the\n"
         "                       sensor, and DIR/imu.yaml, the imu.* parameters of its mount (docs/imu.md);\n"
         "                       with --bag, the samples as sensor_msgs/Imu on /imu (frame imu), the mount\n"
         "                       as velodyne -> imu on /tf_static, and each cloud recorded once its sweep\n"
         "                       and the samples over it are out\n"
         "  --imu-rate HZ        the IMU's samples a second (default 200)\n"
         "  --stamp-rounding S   record the stamps rounded to S seconds (times.txt, the scans, the bag), as\n"
         "                       KITTI-raw's are to 0.01; the ground truth stays at the true instants\n"
         "                       (default 0: exact)\n"
         "  --truth-at instants|stamps\n"
         "                       where the ground truth is taken: at each scan's true instant (default), or\n"
         "                       at its recorded stamp, as KITTI-raw's OXTS poses are (with --stamp-rounding;\n"
         "                       elo_eval --gt-times moves it back to the instants)\n"
         "  --truth-time-offset S\n"
         "                       record the ground truth S seconds after each scan's stamp (poses.txt, the\n"
         "                       bag's), as KITTI-raw's OXTS poses are off its scans' (default 0)\n"
         "  --threads N          worker threads (default 0: all cores)\n"
         "  --help               this text\n";
}

using elo::tools::UsageError;

struct Options {
  SimulationSpec spec;
  std::string output;
  elo::sim::ScanFormat format = elo::sim::ScanFormat::kitti_bin;
  std::optional<std::string> bag;
  int threads = 0;
  std::optional<elo::sim::ImuGrade> imu;
  double imu_rate = 200.0;
};

long long parseInteger(const std::string& flag, const std::string& text, long long minimum) {
  const long long value = elo::tools::parseNumber<long long>(flag, text);
  if (value < minimum) throw UsageError(flag + " must be at least " + std::to_string(minimum));
  return value;
}

std::map<std::string, std::string> readFlags(int argc, char** argv) {
  static const std::vector<std::string> known = {
      "--world", "--trajectory", "--poses",    "--frames",      "--output",        "--bag",          "--sensor",
      "--seed",  "--config",     "--noise",    "--dropout",     "--deskewed",      "--moving-cars",  "--foliage-depth",
      "--mixed-pixels", "--beam-range-bias", "--beam-elevation-error", "--range-offset", "--lower-block-rise",
      "--threads", "--format", "--time-convention", "--mirror", "--gait", "--stamp-rounding", "--truth-at",
      "--truth-time-offset", "--imu", "--imu-rate"};
  std::map<std::string, std::string> flags;
  for (int i = 1; i < argc; ++i) {
    const std::string flag = argv[i];
    if (std::find(known.begin(), known.end(), flag) == known.end()) throw UsageError("unknown argument '" + flag + "'");
    if (i + 1 >= argc) throw UsageError(flag + " needs a value");
    if (!flags.emplace(flag, argv[++i]).second) throw UsageError(flag + " given twice");
  }
  return flags;
}

Options parseOptions(int argc, char** argv) {
  std::map<std::string, std::string> flags = readFlags(argc, argv);
  const auto take = [&flags](const std::string& flag) -> std::optional<std::string> {
    const auto found = flags.find(flag);
    if (found == flags.end()) return std::nullopt;
    return found->second;
  };
  Options options;
  SimulationSpec& spec = options.spec;

  const auto world = take("--world");
  if (!world) throw UsageError("--world is required");
  const auto family = elo::sim::worldFamilyFromName(*world);
  if (!family) throw UsageError("unknown world '" + *world + "' (" + joined(elo::sim::worldNames()) + ")");
  spec.world = *family;

  const auto output = take("--output");
  if (!output) throw UsageError("--output is required");
  options.output = *output;
  options.bag = take("--bag");
  if (const auto format = take("--format")) {
    if (*format != "bin" && *format != "pcd") throw UsageError("--format expects bin or pcd");
    options.format = *format == "bin" ? elo::sim::ScanFormat::kitti_bin : elo::sim::ScanFormat::pcd;
  }

  const auto trajectory = take("--trajectory");
  const auto poses = take("--poses");
  if (trajectory.has_value() == poses.has_value()) throw UsageError("give exactly one of --trajectory and --poses");
  if (trajectory) {
    const auto kind = elo::sim::trajectoryKindFromName(*trajectory);
    if (!kind) throw UsageError("unknown trajectory '" + *trajectory + "' (" + joined(elo::sim::trajectoryNames()) + ")");
    spec.trajectory = *kind;
  } else {
    spec.driven_poses = elo::cameraToLidar(elo::readKittiPoses(*poses), elo::sim::kittiVeloToCam00());
  }
  const auto frames = take("--frames");
  if (frames) {
    spec.frames = static_cast<int>(parseInteger("--frames", *frames, 1));
  } else if (poses) {
    spec.frames = static_cast<int>(spec.driven_poses.size());
  } else {
    throw UsageError("--frames is required with --trajectory");
  }
  if (poses && spec.frames > static_cast<int>(spec.driven_poses.size())) {
    throw UsageError("--frames " + std::to_string(spec.frames) + " exceeds the " +
                     std::to_string(spec.driven_poses.size()) + " poses of " + *poses);
  }

  const std::string sensor = take("--sensor").value_or("hdl64");
  const std::vector<std::string> sensors = elo::sim::sensorNames();
  if (std::find(sensors.begin(), sensors.end(), sensor) == sensors.end()) {
    throw UsageError("unknown sensor '" + sensor + "' (" + joined(sensors) + ")");
  }
  elo::sim::loadSensor(sensor, spec.config);
  if (const auto config = take("--config")) elo::loadConfigYaml(*config, spec.config);

  if (const auto seed = take("--seed")) spec.seed = static_cast<uint64_t>(parseInteger("--seed", *seed, 0));
  if (const auto noise = take("--noise")) {
    spec.config.sensor.range_noise_stddev = elo::tools::parseNumber<double>("--noise", *noise);
    if (spec.config.sensor.range_noise_stddev < 0.0) throw UsageError("--noise must not be negative");
  }
  if (const auto dropout = take("--dropout")) {
    spec.lidar.dropout_probability = elo::tools::parseNumber<double>("--dropout", *dropout);
    if (spec.lidar.dropout_probability < 0.0 || spec.lidar.dropout_probability > 1.0) {
      throw UsageError("--dropout must lie in [0, 1]");
    }
  }
  if (const auto deskewed = take("--deskewed")) {
    if (*deskewed != "0" && *deskewed != "1") throw UsageError("--deskewed expects 0 or 1");
    spec.lidar.deskewed = *deskewed == "1";
  }
  if (const auto convention = take("--time-convention")) {
    if (*convention != "field" && *convention != "azimuth") throw UsageError("--time-convention expects field or azimuth");
    // An instantaneous scan has no times to tell: the option would silently do nothing.
    if (spec.lidar.deskewed) throw UsageError("--time-convention needs --deskewed 0");
    spec.lidar.time_convention =
        *convention == "field" ? elo::sim::TimeConvention::field : elo::sim::TimeConvention::azimuth;
  }
  if (const auto cars = take("--moving-cars")) spec.moving_cars = static_cast<int>(parseInteger("--moving-cars", *cars, 0));
  if (const auto depth = take("--foliage-depth")) {
    spec.lidar.foliage_depth = elo::tools::parseNumber<double>("--foliage-depth", *depth);
    if (spec.lidar.foliage_depth < 0.0) throw UsageError("--foliage-depth must not be negative");
  }
  if (const auto mixed = take("--mixed-pixels")) {
    spec.lidar.mixed_pixel_probability = elo::tools::parseNumber<double>("--mixed-pixels", *mixed);
    if (spec.lidar.mixed_pixel_probability < 0.0 || spec.lidar.mixed_pixel_probability > 1.0) {
      throw UsageError("--mixed-pixels must lie in [0, 1]");
    }
  }
  if (const auto bias = take("--beam-range-bias")) {
    spec.lidar.beam_range_bias = elo::tools::parseNumber<double>("--beam-range-bias", *bias);
    if (spec.lidar.beam_range_bias < 0.0) throw UsageError("--beam-range-bias must not be negative");
  }
  if (const auto error = take("--beam-elevation-error")) {
    spec.lidar.beam_elevation_error = elo::tools::parseNumber<double>("--beam-elevation-error", *error);
    if (spec.lidar.beam_elevation_error < 0.0) throw UsageError("--beam-elevation-error must not be negative");
  }
  if (const auto offset = take("--range-offset")) {
    spec.lidar.range_offset = elo::tools::parseNumber<double>("--range-offset", *offset);
    if (std::abs(spec.lidar.range_offset) > 1.0) throw UsageError("--range-offset must lie within [-1, 1] m");
  }
  if (const auto rise = take("--lower-block-rise")) {
    spec.lidar.lower_block_rise = elo::tools::parseNumber<double>("--lower-block-rise", *rise);
  }
  if (const auto mirror = take("--mirror")) {
    if (*mirror != "0" && *mirror != "1") throw UsageError("--mirror expects 0 or 1");
    spec.mirrored = *mirror == "1";
  }
  if (const auto gait = take("--gait")) {
    const std::optional<elo::sim::Gait> named = elo::sim::gaitFromName(*gait);
    if (!named) throw UsageError("--gait expects " + joined(elo::sim::gaitNames()) + ", got '" + *gait + "'");
    spec.gait = *named;
  }
  if (const auto grade = take("--imu")) {
    options.imu = elo::sim::imuGradeFromName(*grade);
    if (!options.imu) throw UsageError("--imu expects " + joined(elo::sim::imuGradeNames()) + ", got '" + *grade + "'");
  }
  if (const auto rate = take("--imu-rate")) {
    options.imu_rate = elo::tools::parseNumber<double>("--imu-rate", *rate);
    if (!(options.imu_rate > 0.0)) throw UsageError("--imu-rate must be positive");
  }
  if (const auto rounding = take("--stamp-rounding")) {
    spec.stamp_rounding = elo::tools::parseNumber<double>("--stamp-rounding", *rounding);
    if (!(spec.stamp_rounding >= 0.0)) throw UsageError("--stamp-rounding must not be negative");
  }
  if (const auto truth_at = take("--truth-at")) {
    if (*truth_at != "instants" && *truth_at != "stamps") {
      throw UsageError("--truth-at expects instants or stamps, got '" + *truth_at + "'");
    }
    spec.truth_at_recorded_stamps = *truth_at == "stamps";
  }
  if (const auto offset = take("--truth-time-offset")) {
    spec.truth_time_offset = elo::tools::parseNumber<double>("--truth-time-offset", *offset);
    if (!std::isfinite(spec.truth_time_offset)) throw UsageError("--truth-time-offset must be a finite number");
  }
  if (const auto threads = take("--threads")) options.threads = static_cast<int>(parseInteger("--threads", *threads, 0));
  return options;
}

// DIR/imu.txt, and DIR/imu.yaml: the imu.* parameters that say where the simulated IMU sits; with --bag,
// the samples on its /imu and the mount on its /tf_static.
void writeImu(const elo::sim::Simulation& simulation, const Options& options, elo_ros::SequenceBagWriter* bag) {
  const std::vector<elo::ImuSample> samples =
      elo::sim::simulateImu(simulation, *options.imu, options.imu_rate, options.spec.seed);
  elo::writeImuFile(options.output + "/imu.txt", samples);
  if (bag && !samples.empty()) {
    bag->writeImuMount(elo::sim::simulatedImuMount(), samples.front().stamp);
    for (const elo::ImuSample& sample : samples) bag->write(sample);
  }
  const auto listed = [](const std::vector<double>& values) {
    return "[" + std::to_string(values[0]) + ", " + std::to_string(values[1]) + ", " + std::to_string(values[2]) + "]";
  };
  std::ofstream yaml(options.output + "/imu.yaml");
  yaml << "# Where elo_sim's IMU sits on the sensor (docs/imu.md).\nimu:\n  enabled: true\n  position: "
       << listed(elo::sim::imuMountPosition()) << "\n  rotation_deg: " << listed(elo::sim::imuMountRotationDeg()) << "\n";
  if (!yaml.flush()) throw std::runtime_error("cannot write " + options.output + "/imu.yaml");
}

// With an IMU, each cloud is recorded when a driver would publish it: after the sweep's end, the instant
// up to which the odometry integrates the gyro over it (mid-sweep, where the stamp is for azimuth times
// and instantaneous scans, plus half a sweep), and the IMU's next sample. Played back, a node then has the
// samples over a sweep when its cloud comes.
elo_ros::SequenceBagOptions bagOptions(const Options& options) {
  elo_ros::SequenceBagOptions bag;
  if (!options.imu) return bag;
  const bool stamped_at_start =
      !options.spec.lidar.deskewed && options.spec.lidar.time_convention == elo::sim::TimeConvention::field;
  bag.cloud_record_delay =
      (stamped_at_start ? 1.0 : 0.5) / options.spec.config.sensor.rotation_rate_hz + 1.0 / options.imu_rate;
  return bag;
}

int run(const Options& options) {
  const auto start = std::chrono::steady_clock::now();
  tbb::task_arena arena(options.threads > 0 ? options.threads : tbb::task_arena::automatic);
  elo::sim::SequenceSummary summary;
  // --bag: the scans go to the bag as they are simulated, with the ring and any per-point times that
  // the KITTI .bin files cannot hold.
  std::optional<elo_ros::SequenceBagWriter> bag;
  if (options.bag) bag.emplace(*options.bag, bagOptions(options));
  const elo::sim::ScanSink to_bag = [&bag](const elo::sim::SimulatedScan& scan, const Eigen::Isometry3d& pose) {
    bag->write(scan.cloud, pose);
  };
  arena.execute([&] {
    const elo::sim::Simulation simulation(options.spec);
    summary = elo::sim::writeSequence(simulation, options.output, options.format,
                                      bag ? to_bag : elo::sim::ScanSink());
    if (options.imu) writeImu(simulation, options, bag ? &*bag : nullptr);
  });
  if (bag) bag->close();
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  std::printf("wrote %d scans (%.0f points a scan) of %s to %s in %.1f s (%.1f scans/s, %d threads)\n",
              summary.frames, static_cast<double>(summary.points) / summary.frames,
              options.spec.config.sensor.name.c_str(), options.output.c_str(), seconds, summary.frames / seconds,
              arena.max_concurrency());
  if (bag) std::printf("wrote the scans with ground truth to the bag %s\n", options.bag->c_str());
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  for (int i = 1; i < argc; ++i) {
    if (std::string(argv[i]) == "--help" || std::string(argv[i]) == "-h") {
      std::cout << usage();
      return 0;
    }
  }
  Options options;
  try {
    options = parseOptions(argc, argv);
  } catch (const UsageError& error) {
    std::cerr << "elo_sim: " << error.what() << "\nTry 'elo_sim --help'.\n";
    return kUsageError;
  } catch (const std::exception& error) {
    // A sensor or config file, or a poses file, that cannot be read or used: also the caller's input.
    std::cerr << "elo_sim: " << error.what() << "\n";
    return kUsageError;
  }
  try {
    return run(options);
  } catch (const std::exception& error) {
    std::cerr << "elo_sim: " << error.what() << "\n";
    return 1;
  }
}
