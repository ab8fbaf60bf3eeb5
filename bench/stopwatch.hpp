// Wall-clock seconds for the benchmarks' timings.
#pragma once

#include <chrono>

namespace mlmap::bench {

using Clock = std::chrono::steady_clock;

inline double secondsSince(Clock::time_point start) {
  return std::chrono::duration<double>(Clock::now() - start).count();
}

}  // namespace mlmap::bench
