#include "elo/sim/sequence_writer.hpp"

#include <tbb/parallel_for.h>

#include <atomic>
#include <cstdio>
#include <filesystem>
#include <vector>

#include "elo/io/io_error.hpp"
#include "elo/io/kitti.hpp"

namespace elo::sim {
namespace {

std::string scanPath(const std::filesystem::path& velodyne, int frame) {
  char name[16];
  std::snprintf(name, sizeof(name), "%06d.bin", frame);
  return (velodyne / name).string();
}

}  // namespace

SequenceSummary writeSequence(const Simulation& simulation, const std::string& directory) {
  const std::filesystem::path root(directory);
  const std::filesystem::path velodyne = root / "velodyne";
  std::error_code error;
  std::filesystem::create_directories(velodyne, error);
  if (error) throw IoError("cannot create '" + velodyne.string() + "': " + error.message());

  const int frames = simulation.frameCount();
  std::vector<Eigen::Isometry3d> poses(frames);
  std::vector<double> stamps(frames);
  std::atomic<size_t> points{0};
  tbb::parallel_for(0, frames, [&](int frame) {
    const SimulatedScan scan = simulation.scan(frame);
    writeKittiBin(scanPath(velodyne, frame), scan.cloud);
    points += scan.cloud.size();
    poses[frame] = simulation.sensorPose(frame);
    stamps[frame] = simulation.stamp(frame);
  });
  const Eigen::Isometry3d first_inverse = poses.front().inverse();
  for (Eigen::Isometry3d& pose : poses) pose = first_inverse * pose;
  poses.front().setIdentity();  // exactly, not up to rounding
  writeKittiPoses((root / "poses.txt").string(), poses);
  writeTimes((root / "times.txt").string(), stamps);
  writeKittiCalibration((root / "calib.txt").string(), kittiVeloToCam00());
  return {frames, points.load()};
}

}  // namespace elo::sim
