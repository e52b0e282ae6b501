#include "imu_feed.hpp"

#include <filesystem>

#include "elo/io/imu_file.hpp"
#include "elo/io/io_error.hpp"

namespace elo::tools {

ImuFeed::ImuFeed(const std::string& input, const Config& config)
    : sweep_(1.0 / config.sensor.rotation_rate_hz), time_offset_(config.imu.time_offset) {
  if (!config.imu.enabled) return;
  const std::filesystem::path file = std::filesystem::path(input) / "imu.txt";
  if (!std::filesystem::is_regular_file(file)) {
    throw IoError("imu.enabled, but " + file.string() +
                  " is not there: elo_run reads the IMU from the imu.txt of a KITTI-layout directory (docs/imu.md)");
  }
  samples_ = readImuFile(file.string());
}

void ImuFeed::feedUpTo(double stamp, DriveSession& session) {
  // A sweep after the stamp covers the sweep of a scan stamped at its start (`field` times), and more.
  for (; next_ < samples_.size() && samples_[next_].stamp + time_offset_ <= stamp + sweep_; ++next_) {
    session.addImu(samples_[next_]);
  }
}

}  // namespace elo::tools
