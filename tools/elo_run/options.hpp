// elo_run's command line: its usage, its options, and what they give: the configuration, the output
// paths and the scans played.
#pragma once

#include <Eigen/Geometry>
#include <string>
#include <utility>
#include <vector>

#include "elo/config.hpp"
#include "elo/io/scan_source.hpp"

namespace elo::tools {

extern const char kEloRunUsage[];

struct Options {
  std::string input;
  std::string topic;
  std::string imu_topic;  // --imu-topic
  std::string output;
  std::vector<std::string> config_files;  // applied in order
  std::string timing_csv;
  std::string tum_output;
  std::string camera_output;
  std::string map_output;
  std::string localize_map;
  Eigen::Isometry3d initial_pose = Eigen::Isometry3d::Identity();
  std::vector<std::pair<std::string, std::string>> overrides;
  size_t max_frames = 0;
  size_t stride = 1;
  size_t start = 0;
  bool reverse = false;
  bool strict = false;
  bool prefetch = true;
  bool quiet = false;
  bool dump_config = false;
};

// Throws UsageError (command_line.hpp) for flags that cannot work together or values that cannot be used.
Options parseArguments(int argc, char** argv);
// The defaults, --config's files in order, then --set and the flags that stand for parameters; validated.
Config loadConfig(const Options& options);
// --camera-output, or POSES with _camera before its extension.
std::string cameraOutputPath(const Options& options);
// The scans the run plays (playOrder), each at its recorded stamp: the odometry starts at the first scan
// it is given, whatever its stamp.
std::vector<PlayedScan> playedScans(const ScanSource& source, const Options& options);

}  // namespace elo::tools
