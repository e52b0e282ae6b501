// imu.txt beside a KITTI-layout sequence (docs/imu.md): one IMU sample a line, `t wx wy wz ax ay az`:
// t in seconds on the clock of the directory's times.txt, the rates in rad/s and the specific force
// (gravity included) in m/s^2, both in the IMU's axes. Blank lines are skipped.
#pragma once

#include <istream>
#include <string>
#include <vector>

#include "elo/imu/imu_track.hpp"

namespace elo {

// Throws IoError naming the file and line of a row without seven numbers.
std::vector<ImuSample> readImuFile(const std::string& path);
std::vector<ImuSample> readImuFile(std::istream& stream, const std::string& name);
void writeImuFile(const std::string& path, const std::vector<ImuSample>& samples);

}  // namespace elo
