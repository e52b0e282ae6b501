// elo_run: runs the odometry over a sequence on disk (KITTI layout or a directory of PCD/BIN scans) or a
// ROS 1 or ROS 2 bag, and writes the trajectory. A shell over elo::DriveSession (docs/architecture.md):
// parse flags, read scans (elo_run/scan_loop), write the poses, the map and the summary.
#include <chrono>
#include <cstdio>
#include <iostream>
#include <memory>
#include <string>
#include <vector>

#include "command_line.hpp"
#include "elo/drive_session.hpp"
#include "elo/io/config_yaml.hpp"
#include "elo/io/kitti.hpp"
#include "elo/io/scan_source.hpp"
#include "elo/sensor/sensor_fit.hpp"
#include "elo_run/localization_output.hpp"
#include "elo_run/map_output.hpp"
#include "elo_run/options.hpp"
#include "elo_run/scan_loop.hpp"
#include "scan_sources.hpp"

namespace elo::tools {
namespace {

// The first `lines` lines of the session's trajectory (the sensor's poses, in the map when localizing),
// in KITTI format, in the camera frame with a calibration, and in TUM format with --tum.
void writeTrajectory(const Options& options, const ScanSource& source, const DriveSession& session, size_t lines) {
  const DriveTrajectory trajectory = session.trajectory();
  std::vector<Eigen::Isometry3d> poses = session.localizer() ? trajectory.in_map : trajectory.odometry;
  if (session.localizer()) {
    for (const DriveTrajectory::Placement& placed : trajectory.placements) {
      for (size_t line : placed.lines) poses[line] = placed.correction * poses[line];
    }
  }
  std::vector<double> stamps = trajectory.stamps;
  poses.resize(lines);
  stamps.resize(lines);
  writeKittiPoses(options.output, poses);
  if (source.hasCalibration()) writeKittiPoses(cameraOutputPath(options), lidarToCamera(poses, source.calibration()));
  if (!options.tum_output.empty()) writeTumPoses(options.tum_output, stamps, poses);
}

std::unique_ptr<ScanSource> openSource(const Options& options) {
  const auto opening = std::chrono::steady_clock::now();
  std::unique_ptr<ScanSource> source = elo_ros::openScanSource(options.input, options.topic);
  std::printf("input: %s, %zu scans, listed in %.2f s\n", source->describe().c_str(), source->size(),
              std::chrono::duration<double>(std::chrono::steady_clock::now() - opening).count());
  if (!source->warning().empty()) std::fprintf(stderr, "warning: %s\n", source->warning().c_str());
  return source;
}

std::unique_ptr<DriveSession> startSession(const Options& options, const Config& config) {
  DriveSessionOptions session_options;
  session_options.build_map = !options.map_output.empty();
  // Scans waiting for the map's thread; it adds a scan in a tenth of the time the odometry takes.
  session_options.map_queue = 32;
  auto session = std::make_unique<DriveSession>(config, session_options);
  const std::string& backend_warning = session->odometry().backendWarning();
  if (!backend_warning.empty()) std::fprintf(stderr, "warning: %s\n", backend_warning.c_str());
  const std::string normal_reach = normalReachWarning(config);
  if (!normal_reach.empty()) std::fprintf(stderr, "warning: %s\n", normal_reach.c_str());
  if (!options.localize_map.empty()) {
    session->localizeIn(loadLocalizationMap(options.localize_map, config), options.initial_pose);
  }
  return session;
}

// The summary: counts and times, the map written and what it cost, the localization's matches.
void printSummary(const Options& options, DriveSession& session, const ScanLoop& loop, size_t scans,
                  double wall_seconds) {
  loop.report().print(session, scans, loop.nonFinitePoints(), wall_seconds);
  for (const auto& [reason, count] : loop.imu().skippedMessages()) {
    std::printf("IMU: %zu message%s skipped (%s)\n", count, count > 1 ? "s" : "", reason.c_str());
  }
  if (session.driveMap()) {
    std::printf("%s\n", writeDriveMap(session, options.map_output).c_str());
    const auto [copy_ms, add_ms] = mapCostPerScan(session);
    std::printf("map cost a processed scan (CPU time): %.2f ms copying points (odometry's thread), %.2f ms adding "
                "them (map's thread); the pipeline took %.1f ms (wall)\n",
                copy_ms, add_ms, loop.report().meanTotalMilliseconds());
  }
  if (session.localizer()) {
    loop.localizationReport()->print(*session.localizer());
    printPlacement(session);
  }
}

int run(const Options& options) {
  const Config config = loadConfig(options);
  if (options.dump_config) {
    std::cout << dumpConfigYaml(config);
    return 0;
  }
  const std::unique_ptr<ScanSource> source = openSource(options);
  const std::vector<PlayedScan> played = playedScans(*source, options);
  const std::unique_ptr<DriveSession> session = startSession(options, config);
  ScanLoop loop(options, *source, *session);
  const auto start = std::chrono::steady_clock::now();
  try {
    loop.run(played);
  } catch (const std::exception&) {
    writeTrajectory(options, *source, *session, loop.completed());
    if (session->localizer()) printPlacement(*session);
    std::fprintf(stderr, "\nelo_run: stopped after %zu of %zu scans; their poses are in %s\n", loop.completed(),
                 played.size(), options.output.c_str());
    if (session->driveMap()) writeDriveMapAfterFailure(*session, options.map_output);
    throw;
  }
  const double wall_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  writeTrajectory(options, *source, *session, loop.completed());
  printSummary(options, *session, loop, played.size(), wall_seconds);
  return 0;
}

}  // namespace
}  // namespace elo::tools

int main(int argc, char** argv) {
  using namespace elo::tools;
  return runTool("elo_run", kEloRunUsage, argc, argv, [&] { return run(parseArguments(argc, argv)); });
}
