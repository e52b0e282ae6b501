// What the node says of each scan the drive session took: restarts, warnings, the start search, tracking
// health and skips, in its log and its diagnostics' counts.
#pragma once

#include <string>

#include "diagnostics.hpp"
#include "elo/drive_session.hpp"

namespace elo_ros {

class StepLog {
 public:
  // `name`: the nodelet's, which its messages are logged under.
  StepLog(std::string name, const elo::Config& config, PipelineStatistics& statistics)
      : name_(std::move(name)), config_(config), statistics_(statistics) {}

  void log(const elo::DriveStep& step);

 private:
  // Warns and counts when the odometry restarted at this scan.
  void logRestart(const elo::DriveStep& step);
  // Says where the start search put a start in motion (a warning when the scans could not tell), and
  // warns of a gap, whose motion was searched.
  void logStartSearch(const elo::FrameResult& result);
  // Says when a registration was refused, the track recovered or the sensor height does not fit.
  void logTrackingHealth(const elo::FrameResult& result);

  std::string name_;
  elo::Config config_;
  PipelineStatistics& statistics_;
};

}  // namespace elo_ros
