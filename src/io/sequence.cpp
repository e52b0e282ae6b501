#include "elo/io/sequence.hpp"

#include <algorithm>
#include <filesystem>
#include <stdexcept>

#include "elo/io/io_error.hpp"
#include "elo/io/kitti.hpp"
#include "elo/io/pcd.hpp"

namespace elo {
namespace {

namespace fs = std::filesystem;

constexpr double kDefaultScanPeriod = 0.1;  // s: a spinning LiDAR at 10 Hz, as KITTI's HDL-64E

std::vector<std::string> sortedFilesWithExtension(const fs::path& directory, const std::string& extension) {
  std::vector<std::string> paths;
  for (const fs::directory_entry& entry : fs::directory_iterator(directory)) {
    if (entry.is_regular_file() && entry.path().extension() == extension) {
      paths.push_back(entry.path().string());
    }
  }
  std::sort(paths.begin(), paths.end());
  return paths;
}

void requireCountMatches(const std::string& side_file, size_t lines, size_t scans) {
  if (lines != scans) {
    throw IoError("'" + side_file + "' has " + std::to_string(lines) + " entries but the sequence has " +
                  std::to_string(scans) + " scans");
  }
}

}  // namespace

Sequence::Sequence(const std::string& directory) : directory_(directory) {
  if (!fs::is_directory(directory_)) {
    throw IoError("sequence directory '" + directory_ + "' does not exist or is not a directory");
  }
  findScans();
  readSideFiles();
}

void Sequence::findScans() {
  const fs::path velodyne = fs::path(directory_) / "velodyne";
  if (fs::is_directory(velodyne)) {
    scan_paths_ = sortedFilesWithExtension(velodyne, ".bin");
    if (scan_paths_.empty()) {
      throw IoError("'" + velodyne.string() + "' holds no .bin scans");
    }
    return;
  }
  const std::vector<std::string> pcd_paths = sortedFilesWithExtension(directory_, ".pcd");
  const std::vector<std::string> bin_paths = sortedFilesWithExtension(directory_, ".bin");
  if (!pcd_paths.empty() && !bin_paths.empty()) {
    throw IoError("'" + directory_ + "' mixes .pcd and .bin scans; keep one format per sequence");
  }
  if (pcd_paths.empty() && bin_paths.empty()) {
    throw IoError("'" + directory_ + "' holds no scans (no velodyne/*.bin, *.pcd or *.bin)");
  }
  scans_are_pcd_ = !pcd_paths.empty();
  scan_paths_ = scans_are_pcd_ ? pcd_paths : bin_paths;
}

void Sequence::readSideFiles() {
  const fs::path root(directory_);
  if (const fs::path times = root / "times.txt"; fs::exists(times)) {
    stamps_ = readTimes(times.string());
    requireCountMatches(times.string(), stamps_.size(), size());
  }
  if (const fs::path poses = root / "poses.txt"; fs::exists(poses)) {
    ground_truth_ = readKittiPoses(poses.string());
    requireCountMatches(poses.string(), ground_truth_.size(), size());
  }
  if (const fs::path calib = root / "calib.txt"; fs::exists(calib)) {
    calibration_ = readKittiCalibration(calib.string());
  }
}

void Sequence::checkIndex(size_t index) const {
  if (index >= size()) {
    throw std::out_of_range("scan " + std::to_string(index) + " of a sequence of " + std::to_string(size()) +
                            " in '" + directory_ + "'");
  }
}

const std::string& Sequence::path(size_t index) const {
  checkIndex(index);
  return scan_paths_[index];
}

PointCloud Sequence::load(size_t index, size_t* non_finite_skipped) const {
  const std::string& scan_path = path(index);
  PointCloud cloud;
  if (scans_are_pcd_) {
    cloud = readPcd(scan_path, non_finite_skipped);
  } else {
    cloud = readKittiBin(scan_path);
    if (non_finite_skipped != nullptr) {
      *non_finite_skipped = 0;  // .bin scans are returned exactly as stored
    }
  }
  cloud.stamp = stamp(index);
  return cloud;
}

LoadedScan Sequence::read(size_t index) const {
  LoadedScan scan;
  try {
    scan.cloud = load(index, &scan.non_finite_points);
  } catch (const IoError& error) {
    throw UnusableScan("scan file unreadable", error.what());
  }
  return scan;
}

double Sequence::stamp(size_t index) const {
  checkIndex(index);
  return stamps_.empty() ? kDefaultScanPeriod * static_cast<double>(index) : stamps_[index];
}

const Eigen::Isometry3d& Sequence::calibration() const {
  if (!calibration_) {
    throw IoError("sequence '" + directory_ + "' has no calib.txt");
  }
  return *calibration_;
}

const std::vector<Eigen::Isometry3d>& Sequence::groundTruth() const {
  if (ground_truth_.empty()) {
    throw IoError("sequence '" + directory_ + "' has no poses.txt");
  }
  return ground_truth_;
}

}  // namespace elo
