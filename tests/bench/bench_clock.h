// The clocks the benchmarks read, in milliseconds: one definition instead of one per program.
#pragma once

#include <chrono>
#include <ctime>

namespace calf::bench {

// Wall clock (monotonic).
inline double now_ms() {
  return std::chrono::duration<double, std::milli>(
             std::chrono::steady_clock::now().time_since_epoch())
      .count();
}

// CPU time of the calling thread: steadier than the wall clock on a shared machine (time another
// process takes from the core does not count), and what "decode CPU ms" means.
inline double thread_cpu_ms() {
  timespec ts{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
  return ts.tv_sec * 1e3 + ts.tv_nsec / 1e6;
}

}  // namespace calf::bench
