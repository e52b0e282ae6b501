#include "elo/sim/sequence_writer.hpp"

// TBB_VERSION_MAJOR: oneTBB (2021 on) defines it in tbb/version.h, TBB 2020 (Noetic, Debian 11) in
// tbb/tbb_stddef.h. oneTBB has the pipeline in its own header and the filter modes in tbb::filter_mode;
// TBB 2020 in tbb/pipeline.h, the modes in tbb::filter.
#if __has_include(<tbb/version.h>)
#include <tbb/version.h>
#else
#include <tbb/tbb_stddef.h>
#endif
#if TBB_VERSION_MAJOR >= 2021
#include <tbb/parallel_pipeline.h>
#else
#include <tbb/pipeline.h>
#endif
#include <tbb/task_arena.h>

#include <cstdio>
#include <filesystem>
#include <memory>
#include <vector>

#include "elo/io/io_error.hpp"
#include "elo/io/kitti.hpp"
#include "elo/io/pcd.hpp"

namespace elo::sim {
namespace {

#if TBB_VERSION_MAJOR >= 2021
using FilterMode = tbb::filter_mode;
#else
using FilterMode = tbb::filter;
#endif

std::filesystem::path scanDirectory(const std::filesystem::path& root, ScanFormat format) {
  return format == ScanFormat::kitti_bin ? root / "velodyne" : root;
}

void writeScan(const std::filesystem::path& scans, ScanFormat format, int frame, const PointCloud& cloud) {
  char name[16];
  std::snprintf(name, sizeof(name), format == ScanFormat::kitti_bin ? "%06d.bin" : "%06d.pcd", frame);
  const std::string path = (scans / name).string();
  if (format == ScanFormat::kitti_bin) {
    writeKittiBin(path, cloud);
  } else {
    writePcd(path, cloud);
  }
}

}  // namespace

SequenceSummary writeSequence(const Simulation& simulation, const std::string& directory, ScanFormat format,
                              const ScanSink& sink) {
  const std::filesystem::path root(directory);
  const std::filesystem::path scans = scanDirectory(root, format);
  std::error_code error;
  std::filesystem::create_directories(scans, error);
  if (error) throw IoError("cannot create '" + scans.string() + "': " + error.message());

  const int frames = simulation.frameCount();
  const Eigen::Isometry3d first_inverse = simulation.recordedTruth(0).inverse();
  std::vector<Eigen::Isometry3d> poses(frames);
  std::vector<double> stamps(frames);
  size_t points = 0;
  // Scans are simulated and written in parallel, then handed on in frame order; a few per thread in
  // flight keep every core busy without holding the whole sequence in memory.
  struct Frame {
    int index;
    std::shared_ptr<const SimulatedScan> scan;
  };
  int next = 0;
  const size_t in_flight = 2 * static_cast<size_t>(tbb::this_task_arena::max_concurrency());
  tbb::parallel_pipeline(
      in_flight,
      tbb::make_filter<void, int>(FilterMode::serial_in_order,
                                  [&](tbb::flow_control& control) {
                                    if (next == frames) control.stop();
                                    return next++;
                                  }) &
          tbb::make_filter<int, Frame>(FilterMode::parallel,
                                       [&](int frame) {
                                         auto scan = std::make_shared<const SimulatedScan>(simulation.scan(frame));
                                         writeScan(scans, format, frame, scan->cloud);
                                         return Frame{frame, std::move(scan)};
                                       }) &
          tbb::make_filter<Frame, void>(FilterMode::serial_in_order, [&](const Frame& frame) {
            poses[frame.index] = frame.index == 0 ? Eigen::Isometry3d::Identity()  // exactly, not up to rounding
                                                  : first_inverse * simulation.recordedTruth(frame.index);
            stamps[frame.index] = simulation.recordedStamp(frame.index);
            points += frame.scan->cloud.size();
            if (sink) sink(*frame.scan, poses[frame.index]);
          }));
  writeKittiPoses((root / "poses.txt").string(), poses);
  writeTimes((root / "times.txt").string(), stamps);
  writeKittiCalibration((root / "calib.txt").string(), kittiVeloToCam00());
  return {frames, points};
}

}  // namespace elo::sim
