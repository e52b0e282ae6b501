// Writes a simulation as a sequence that elo::Sequence reads: the scans, DIR/poses.txt (ground truth
// in the sensor frame at each scan's reference instant: scan i's pose in the frame of scan 0, so scan 0
// is the identity), DIR/times.txt (the scans' stamps, their reference instants) and DIR/calib.txt
// (KITTI 00's Tr, for devkit users who want camera-frame poses: P_cam = Tr * P * Tr^-1).
#pragma once

#include <cstddef>
#include <functional>
#include <string>

#include "elo/sim/simulation.hpp"

namespace elo::sim {

enum class ScanFormat {
  kitti_bin,  // DIR/velodyne/%06d.bin (KITTI's layout): x y z intensity, neither ring nor time
  pcd,        // DIR/%06d.pcd (the flat layout): x y z intensity ring, and time when the scans have times
};

struct SequenceSummary {
  int frames = 0;
  size_t points = 0;
};

// Receives each simulated scan with the sensor's ground-truth pose in the frame of scan 0, in frame
// order, one call at a time: the scan keeps the fields a KITTI .bin cannot hold (ring, per-point time).
using ScanSink = std::function<void(const SimulatedScan& scan, const Eigen::Isometry3d& ground_truth)>;

// Frames are simulated in parallel (in the caller's TBB arena), with a bounded number in flight.
// Throws IoError when a file cannot be written; whatever `sink` throws ends the run.
SequenceSummary writeSequence(const Simulation& simulation, const std::string& directory,
                              ScanFormat format = ScanFormat::kitti_bin, const ScanSink& sink = {});

}  // namespace elo::sim
