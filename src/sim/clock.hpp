// Integer-tick time: one master tick is the plant step; simulated time is tick * period, never a
// running floating-point sum.
#pragma once

#include <cstdint>

namespace quadcosim::sim {

using Tick = std::int64_t;

struct TickClock {
  std::int64_t period_ns = 10'000'000;  ///< plant period [ns]

  std::int64_t ns(Tick k) const { return k * period_ns; }
  double seconds(Tick k) const { return static_cast<double>(k * period_ns) / 1e9; }
  double period_s() const { return static_cast<double>(period_ns) / 1e9; }
};

}  // namespace quadcosim::sim
