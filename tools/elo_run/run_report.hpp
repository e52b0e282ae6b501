// elo_run's summary of the run: the scans processed and skipped, tracking health, each stage's mean and
// median time, FPS and peak memory.
#pragma once

#include <map>
#include <string>
#include <vector>

#include "elo/drive_session.hpp"

namespace elo::tools {

class RunReport {
 public:
  // `prefetching`: each scan went up to a device while the one before it was processed.
  explicit RunReport(bool prefetching) : prefetching_(prefetching) {}

  // A processed scan's stage times, and how long it waited for scans to reach a device
  // (DriveStep::upload_milliseconds; 0 on the CPU backend).
  void add(const DriveStep& step);
  // How long reading one scan took (file or message, decoded and converted): outside the pipeline's total.
  void addReading(double milliseconds) { reading_.push_back(milliseconds); }
  double meanTotalMilliseconds() const;

  void print(const DriveSession& session, size_t scans, size_t non_finite_points, double wall_seconds) const;

 private:
  bool prefetching_;
  std::vector<double> projection_, upload_, features_, registration_, model_update_, total_, reading_;
};

}  // namespace elo::tools
