#pragma once
// The benchmarks' clocks and their one statistic: wall seconds since a moment, the CPU time of the
// process (all threads) and of the calling thread, and the median of repeated runs. On a machine
// shared with other jobs the wall clock also counts the time spent waiting for a core, which the
// CPU clocks do not.
#include <time.h>

#include <algorithm>
#include <chrono>
#include <vector>

namespace pwl::app {

using BenchClock = std::chrono::steady_clock;

inline double seconds_since(BenchClock::time_point start) {
  return std::chrono::duration<double>(BenchClock::now() - start).count();
}

inline double cpu_seconds() {
  timespec ts{};
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
  return static_cast<double>(ts.tv_sec) + 1e-9 * static_cast<double>(ts.tv_nsec);
}

inline double thread_seconds() {
  timespec ts{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
  return static_cast<double>(ts.tv_sec) + 1e-9 * static_cast<double>(ts.tv_nsec);
}

// The median of `v` (0 for none): the middle value, or the mean of the two middle ones.
inline double median(std::vector<double> v) {
  if (v.empty()) return 0.0;
  std::sort(v.begin(), v.end());
  const std::size_t n = v.size();
  return n % 2 == 1 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

}  // namespace pwl::app
