// Wall time of the host's work, for the stage times the odometry and the backends report.
#pragma once

#include <chrono>

namespace elo {

using Clock = std::chrono::steady_clock;

inline double millisecondsSince(Clock::time_point start) {
  return std::chrono::duration<double, std::milli>(Clock::now() - start).count();
}

}  // namespace elo
