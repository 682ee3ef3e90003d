#pragma once

#include <chrono>

namespace ecv {

/// The clock of every stage timing.
using Clock = std::chrono::steady_clock;

/// Milliseconds of wall time since `start`.
inline double MillisecondsSince(Clock::time_point start) {
  return std::chrono::duration<double, std::milli>(Clock::now() - start).count();
}

}  // namespace ecv
