// The KITTI odometry file formats: velodyne/*.bin scans, times.txt, poses (camera frame, row-major 3x4)
// and calib.txt; plus TUM trajectories for tools such as evo. Every reader throws IoError naming the
// file (and the line for text files).
#pragma once

#include <Eigen/Geometry>
#include <istream>
#include <string>
#include <vector>

#include "elo/types.hpp"

namespace elo {

// N x 4 float32 (x, y, z, intensity). `stamp` is left at 0: times come from times.txt.
PointCloud readKittiBin(const std::string& path);
// Writes intensity 0 for a cloud without intensities.
void writeKittiBin(const std::string& path, const PointCloud& cloud);

// One time (s) a line.
std::vector<double> readTimes(const std::string& path);
void writeTimes(const std::string& path, const std::vector<double>& stamps);

// 12 numbers a line: the row-major 3x4 [R|t] of each frame in the frame of frame 0. Written with the
// shortest text that reads back to the same double.
std::vector<Eigen::Isometry3d> readKittiPoses(const std::string& path);
void writeKittiPoses(const std::string& path, const std::vector<Eigen::Isometry3d>& poses);

// `t x y z qx qy qz qw` a line; `stamps` receives the times when not null.
std::vector<Eigen::Isometry3d> readTumPoses(const std::string& path, std::vector<double>* stamps = nullptr);
void writeTumPoses(const std::string& path, const std::vector<double>& stamps,
                   const std::vector<Eigen::Isometry3d>& poses);

// The velodyne->camera transform `Tr` of a KITTI calib.txt (`Tr:` or `Tr_velo_to_cam:`).
Eigen::Isometry3d readKittiCalibration(const std::string& path);
// Writes P0..P3 as [I|0] and `Tr:`, the layout of the odometry devkit's calib.txt.
void writeKittiCalibration(const std::string& path, const Eigen::Isometry3d& velo_to_cam);

// The readers above on an open stream, so that data already in memory needs no file; `name` stands for
// the file in error messages. readKittiBin needs a seekable stream (it checks the size first).
PointCloud readKittiBin(std::istream& stream, const std::string& name);
std::vector<double> readTimes(std::istream& stream, const std::string& name);
std::vector<Eigen::Isometry3d> readKittiPoses(std::istream& stream, const std::string& name);
std::vector<Eigen::Isometry3d> readTumPoses(std::istream& stream, const std::string& name,
                                            std::vector<double>* stamps = nullptr);
Eigen::Isometry3d readKittiCalibration(std::istream& stream, const std::string& name);

// Moves a trajectory between the LiDAR and the camera frame: Tr * P * Tr^-1 and Tr^-1 * P * Tr.
std::vector<Eigen::Isometry3d> lidarToCamera(const std::vector<Eigen::Isometry3d>& lidar_poses,
                                             const Eigen::Isometry3d& velo_to_cam);
std::vector<Eigen::Isometry3d> cameraToLidar(const std::vector<Eigen::Isometry3d>& camera_poses,
                                             const Eigen::Isometry3d& velo_to_cam);

}  // namespace elo
