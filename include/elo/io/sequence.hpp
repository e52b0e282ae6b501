// A sequence of scans on disk, in either of two layouts:
//  - KITTI: DIR/velodyne/*.bin, with optional DIR/times.txt, DIR/calib.txt and DIR/poses.txt;
//  - flat: DIR/*.pcd or DIR/*.bin, with the same optional side files in DIR.
// Scans are ordered by file name. Side files are checked against the scan count when opened, so a
// broken sequence fails at once rather than hundreds of frames into a run.
#pragma once

#include <Eigen/Geometry>
#include <cstddef>
#include <optional>
#include <string>
#include <vector>

#include "elo/io/scan_source.hpp"
#include "elo/types.hpp"

namespace elo {

class Sequence : public ScanSource {
 public:
  // Throws IoError for a missing directory, no scans, mixed .pcd/.bin scans, or a side file that
  // cannot be parsed or whose line count differs from the scan count.
  explicit Sequence(const std::string& directory);

  size_t size() const override { return scan_paths_.size(); }
  const std::string& directory() const { return directory_; }
  const std::string& path(size_t index) const;

  // The scan with its `stamp`: from times.txt, or index * 0.1 s (10 Hz) without one. PCD points with
  // non-finite coordinates are skipped and counted (see readPcd).
  PointCloud load(size_t index, size_t* non_finite_skipped = nullptr) const;
  double stamp(size_t index) const override;
  // load() as a ScanSource: an IoError becomes an UnusableScan counted as "scan file unreadable".
  LoadedScan read(size_t index) const override;
  std::string describe() const override { return "sequence '" + directory_ + "'"; }

  bool hasCalibration() const override { return calibration_.has_value(); }
  // The velodyne->camera `Tr` of calib.txt; throws IoError when the sequence has none.
  const Eigen::Isometry3d& calibration() const override;

  bool hasGroundTruth() const { return !ground_truth_.empty(); }
  // poses.txt as written: for KITTI, camera-frame poses (cameraToLidar converts them).
  const std::vector<Eigen::Isometry3d>& groundTruth() const;

 private:
  void findScans();
  void readSideFiles();
  void checkIndex(size_t index) const;  // throws std::out_of_range

  std::string directory_;
  std::vector<std::string> scan_paths_;
  bool scans_are_pcd_ = false;
  std::vector<double> stamps_;  // empty: 10 Hz from index 0
  std::optional<Eigen::Isometry3d> calibration_;
  std::vector<Eigen::Isometry3d> ground_truth_;
};

}  // namespace elo
