#pragma once
// Wall-clock timing of stages and steps: a steady clock and the milliseconds since a start.
#include <chrono>

namespace vdm {

using Clock = std::chrono::steady_clock;

inline double ms_since(Clock::time_point t0) {
  return std::chrono::duration<double, std::milli>(Clock::now() - t0).count();
}

}  // namespace vdm
