// The monotonic wall clock that DDS waits, timeouts and real-time loops measure with. Never read on
// the lockstep path's simulated time, which is integer ticks (sim/clock.hpp).
#pragma once

#include <chrono>
#include <cstdint>

namespace quadcosim::dds {

/// Monotonic wall clock [ns] (std::chrono::steady_clock).
inline std::int64_t steady_ns() {
  return std::chrono::duration_cast<std::chrono::nanoseconds>(std::chrono::steady_clock::now().time_since_epoch())
      .count();
}

}  // namespace quadcosim::dds
