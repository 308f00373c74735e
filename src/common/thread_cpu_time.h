#pragma once
// CPU time of the calling thread [ms] (CLOCK_THREAD_CPUTIME_ID): a stage's own cost, without
// the time the thread waited preempted on a loaded machine (which wall-clock latency has).

#include <ctime>

namespace sedbridge {

/// CPU time consumed by the calling thread since it started [ms]; 0 if the clock is missing.
inline double ThreadCpuTime_ms() {
  timespec ts{};
  if (clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts) != 0) return 0.0;
  return static_cast<double>(ts.tv_sec) * 1e3 + static_cast<double>(ts.tv_nsec) * 1e-6;
}

}  // namespace sedbridge
