// elo_run's IMU (imu.enabled, docs/imu.md): the samples of the input directory's imu.txt, handed to the
// drive session before each scan, up to the end of its sweep.
#pragma once

#include <string>
#include <vector>

#include "elo/drive_session.hpp"

namespace elo::tools {

class ImuFeed {
 public:
  // Reads DIR/imu.txt of the input directory when `config.imu.enabled`; throws IoError when it is enabled
  // and there is none (or it is malformed).
  ImuFeed(const std::string& input, const Config& config);

  // Hands `session` every sample not handed yet up to a sweep after `stamp` (the scan's).
  void feedUpTo(double stamp, DriveSession& session);

 private:
  double sweep_;       // s
  double time_offset_;  // imu.time_offset
  std::vector<ImuSample> samples_;
  size_t next_ = 0;
};

}  // namespace elo::tools
