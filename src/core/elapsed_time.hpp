// Wall time of the host's work, for the stage times the odometry and the backends report.
#pragma once

#include <time.h>

#include <chrono>

namespace elo {

using Clock = std::chrono::steady_clock;

inline double millisecondsSince(Clock::time_point start) {
  return std::chrono::duration<double, std::milli>(Clock::now() - start).count();
}

// CPU time the calling thread has run (s): unlike wall time, not inflated by other processes' load.
inline double threadCpuSeconds() {
  timespec time{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &time);
  return static_cast<double>(time.tv_sec) + 1e-9 * static_cast<double>(time.tv_nsec);
}

}  // namespace elo
