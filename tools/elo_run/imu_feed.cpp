#include "imu_feed.hpp"

#include <cstdio>
#include <string>

#include "command_line.hpp"
#include "elo/io/bag_imu.hpp"
#include "scan_sources.hpp"

namespace elo::tools {

ImuFeed::ImuFeed(const Options& options, const Config& config)
    : sweep_(1.0 / config.sensor.rotation_rate_hz), time_offset_(config.imu.time_offset) {
  if (!config.imu.enabled) {
    if (!options.imu_topic.empty()) throw UsageError("--imu-topic needs imu.enabled (--set imu.enabled=true)");
    return;
  }
  elo_ros::ImuRecording recording = elo_ros::readImuRecording(options.input, options.imu_topic);
  if (!recording.warning.empty()) std::fprintf(stderr, "warning: %s\n", recording.warning.c_str());
  if (!recording.describe.empty()) std::printf("imu: %s, %zu samples\n", recording.describe.c_str(), recording.samples.size());
  for (const auto& [reason, count] : recording.skipped) {
    std::string line = std::to_string(count) + " IMU message" + (count > 1 ? "s" : "") + " skipped: " + reason;
    if (reason == elo::imu_message::kUnreadable && !recording.unreadable_detail.empty()) {
      line += (count > 1 ? " (the first: " : " (") + recording.unreadable_detail + ")";
    }
    std::fprintf(stderr, "warning: %s\n", line.c_str());
  }
  samples_ = std::move(recording.samples);
  skipped_ = std::move(recording.skipped);
}

void ImuFeed::feedUpTo(double stamp, DriveSession& session) {
  // The sweep of a scan stamped at its start (`field` times) ends a sweep after the stamp, where a sample
  // must lie at or after it: half a sweep more takes that sample whatever the stamps' rounding (a sample
  // stamped at the sweep's end on another clock, a bag's nanoseconds). Samples ahead do no harm.
  for (; next_ < samples_.size() && samples_[next_].stamp + time_offset_ <= stamp + 1.5 * sweep_; ++next_) {
    session.addImu(samples_[next_]);
  }
}

}  // namespace elo::tools
