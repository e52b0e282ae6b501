#include "elo/io/kitti.hpp"

#include <filesystem>

#include "elo/io/io_error.hpp"
#include "text_format.hpp"

namespace elo {
namespace {

constexpr size_t kBinFloatsPerPoint = 4;
constexpr size_t kBinBytesPerPoint = kBinFloatsPerPoint * sizeof(float);
constexpr size_t kPoseMatrixEntries = 12;

Eigen::Isometry3d poseFromRowMajor3x4(const std::vector<double>& entries) {
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
  for (int row = 0; row < 3; ++row) {
    for (int col = 0; col < 4; ++col) {
      pose.matrix()(row, col) = entries[static_cast<size_t>(row * 4 + col)];
    }
  }
  return pose;
}

std::string rowMajor3x4Text(const Eigen::Isometry3d& pose) {
  std::vector<double> entries;
  for (int row = 0; row < 3; ++row) {
    for (int col = 0; col < 4; ++col) {
      entries.push_back(pose.matrix()(row, col));
    }
  }
  return io_detail::formatDoubles(entries);
}

// transform * pose * transform^-1, with a general inverse: KITTI's Tr is orthonormal only to ~1e-8,
// and a transposed "inverse" would not undo it (a round trip through both frames would drift by
// 1e-4 m at 1 km).
std::vector<Eigen::Isometry3d> conjugate(const std::vector<Eigen::Isometry3d>& poses,
                                         const Eigen::Isometry3d& transform) {
  const Eigen::Isometry3d inverse = transform.inverse(Eigen::Affine);
  std::vector<Eigen::Isometry3d> result;
  result.reserve(poses.size());
  for (const Eigen::Isometry3d& pose : poses) {
    result.push_back(transform * pose * inverse);
  }
  return result;
}

// The bytes from the stream's position to its end, leaving the position where it was.
size_t bytesToEnd(std::istream& stream, const std::string& name) {
  const std::streampos start = stream.tellg();
  stream.seekg(0, std::ios::end);
  const std::streampos end = stream.tellg();
  stream.seekg(start);
  if (start < 0 || end < start || !stream) {
    throw IoError("cannot read the size of '" + name + "': the stream cannot seek");
  }
  return static_cast<size_t>(end - start);
}

}  // namespace

PointCloud readKittiBin(const std::string& path) {
  std::ifstream stream = io_detail::openForReading(path, std::ios::binary);
  // A directory opens and seeks like a file of 2^63 bytes: refuse it before sizing a buffer by it.
  if (!std::filesystem::is_regular_file(path)) {
    throw IoError("cannot read '" + path + "': not a regular file");
  }
  return readKittiBin(stream, path);
}

PointCloud readKittiBin(std::istream& stream, const std::string& name) {
  const size_t bytes = bytesToEnd(stream, name);
  if (bytes % kBinBytesPerPoint != 0) {
    throw IoError("'" + name + "' is not a KITTI scan: its size (" + std::to_string(bytes) +
                  " bytes) is not a multiple of 16 (x, y, z, intensity as float32)");
  }
  std::vector<float> values(bytes / sizeof(float));
  if (!stream.read(reinterpret_cast<char*>(values.data()), static_cast<std::streamsize>(bytes))) {
    throw IoError("reading '" + name + "' failed after " + std::to_string(stream.gcount()) + " bytes");
  }
  PointCloud cloud;
  const size_t count = bytes / kBinBytesPerPoint;
  cloud.points.reserve(count);
  cloud.intensity.reserve(count);
  for (size_t i = 0; i < count; ++i) {
    const float* point = values.data() + i * kBinFloatsPerPoint;
    cloud.points.emplace_back(point[0], point[1], point[2]);
    cloud.intensity.push_back(point[3]);
  }
  return cloud;
}

void writeKittiBin(const std::string& path, const PointCloud& cloud) {
  const bool has_intensity = !cloud.intensity.empty();
  std::vector<float> values;
  values.reserve(cloud.size() * kBinFloatsPerPoint);
  for (size_t i = 0; i < cloud.size(); ++i) {
    values.insert(values.end(), {cloud.points[i].x(), cloud.points[i].y(), cloud.points[i].z(),
                                 has_intensity ? cloud.intensity[i] : 0.0f});
  }
  std::ofstream stream = io_detail::openForWriting(path, std::ios::binary);
  stream.write(reinterpret_cast<const char*>(values.data()),
               static_cast<std::streamsize>(values.size() * sizeof(float)));
  io_detail::finishWriting(stream, path);
}

std::vector<double> readTimes(const std::string& path) {
  std::ifstream stream = io_detail::openForReading(path);
  return readTimes(stream, path);
}

std::vector<double> readTimes(std::istream& stream, const std::string& name) {
  std::vector<double> stamps;
  for (const std::vector<double>& row : io_detail::readNumberRows(stream, name, 1)) {
    stamps.push_back(row[0]);
  }
  return stamps;
}

void writeTimes(const std::string& path, const std::vector<double>& stamps) {
  std::ofstream stream = io_detail::openForWriting(path);
  for (double stamp : stamps) {
    stream << io_detail::formatDouble(stamp) << '\n';
  }
  io_detail::finishWriting(stream, path);
}

std::vector<Eigen::Isometry3d> readKittiPoses(const std::string& path) {
  std::ifstream stream = io_detail::openForReading(path);
  return readKittiPoses(stream, path);
}

std::vector<Eigen::Isometry3d> readKittiPoses(std::istream& stream, const std::string& name) {
  std::vector<Eigen::Isometry3d> poses;
  for (const std::vector<double>& row : io_detail::readNumberRows(stream, name, kPoseMatrixEntries)) {
    poses.push_back(poseFromRowMajor3x4(row));
  }
  return poses;
}

void writeKittiPoses(const std::string& path, const std::vector<Eigen::Isometry3d>& poses) {
  std::ofstream stream = io_detail::openForWriting(path);
  for (const Eigen::Isometry3d& pose : poses) {
    stream << rowMajor3x4Text(pose) << '\n';
  }
  io_detail::finishWriting(stream, path);
}

std::vector<Eigen::Isometry3d> readTumPoses(const std::string& path, std::vector<double>* stamps) {
  std::ifstream stream = io_detail::openForReading(path);
  return readTumPoses(stream, path, stamps);
}

std::vector<Eigen::Isometry3d> readTumPoses(std::istream& stream, const std::string& name,
                                            std::vector<double>* stamps) {
  std::vector<Eigen::Isometry3d> poses;
  for (const std::vector<double>& row : io_detail::readNumberRows(stream, name, 8)) {
    Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
    pose.translation() = Eigen::Vector3d(row[1], row[2], row[3]);
    pose.linear() = Eigen::Quaterniond(row[7], row[4], row[5], row[6]).normalized().toRotationMatrix();
    poses.push_back(pose);
    if (stamps != nullptr) {
      stamps->push_back(row[0]);
    }
  }
  return poses;
}

void writeTumPoses(const std::string& path, const std::vector<double>& stamps,
                   const std::vector<Eigen::Isometry3d>& poses) {
  if (stamps.size() != poses.size()) {
    throw IoError("cannot write '" + path + "': " + std::to_string(stamps.size()) + " stamps for " +
                  std::to_string(poses.size()) + " poses");
  }
  std::ofstream stream = io_detail::openForWriting(path);
  for (size_t i = 0; i < poses.size(); ++i) {
    const Eigen::Vector3d& t = poses[i].translation();
    const Eigen::Quaterniond q(poses[i].rotation());
    stream << io_detail::formatDoubles({stamps[i], t.x(), t.y(), t.z(), q.x(), q.y(), q.z(), q.w()}) << '\n';
  }
  io_detail::finishWriting(stream, path);
}

Eigen::Isometry3d readKittiCalibration(const std::string& path) {
  std::ifstream stream = io_detail::openForReading(path);
  return readKittiCalibration(stream, path);
}

Eigen::Isometry3d readKittiCalibration(std::istream& stream, const std::string& name) {
  std::string line;
  for (size_t line_number = 1; std::getline(stream, line); ++line_number) {
    const size_t colon = line.find(':');
    const std::string label = line.substr(0, colon);
    if (colon == std::string::npos || (label != "Tr" && label != "Tr_velo_to_cam")) {
      continue;
    }
    const std::vector<double> entries = io_detail::parseNumbers(line.substr(colon + 1), name, line_number);
    if (entries.size() != kPoseMatrixEntries) {
      throw IoError(name + ":" + std::to_string(line_number) + ": " + label + " needs 12 numbers, found " +
                    std::to_string(entries.size()));
    }
    return poseFromRowMajor3x4(entries);
  }
  throw IoError("'" + name + "' has no 'Tr:' (or 'Tr_velo_to_cam:') line");
}

void writeKittiCalibration(const std::string& path, const Eigen::Isometry3d& velo_to_cam) {
  std::ofstream stream = io_detail::openForWriting(path);
  const std::string projection = rowMajor3x4Text(Eigen::Isometry3d::Identity());
  for (const char* camera : {"P0", "P1", "P2", "P3"}) {
    stream << camera << ": " << projection << '\n';
  }
  stream << "Tr: " << rowMajor3x4Text(velo_to_cam) << '\n';
  io_detail::finishWriting(stream, path);
}

std::vector<Eigen::Isometry3d> lidarToCamera(const std::vector<Eigen::Isometry3d>& lidar_poses,
                                             const Eigen::Isometry3d& velo_to_cam) {
  return conjugate(lidar_poses, velo_to_cam);
}

std::vector<Eigen::Isometry3d> cameraToLidar(const std::vector<Eigen::Isometry3d>& camera_poses,
                                             const Eigen::Isometry3d& velo_to_cam) {
  return conjugate(camera_poses, velo_to_cam.inverse(Eigen::Affine));
}

}  // namespace elo
