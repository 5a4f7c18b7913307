// When a sensor samples and how old its sample is when published.
#pragma once

namespace quadcosim::sensors {

/// A sensor publishes on plant ticks k with k % divider == 0; the sample published at tick k measures
/// the truth of tick max(k - latency_ticks, 0). The message's header stamp is the publication tick
/// (lockstep pairs commands with it); the age is in the data.
struct Timing {
  int divider = 1;        ///< sensor period in plant ticks (rate = plant rate / divider)
  int latency_ticks = 0;  ///< age of the sample when published [plant ticks]
  bool active() const { return divider != 1 || latency_ticks != 0; }
};

}  // namespace quadcosim::sensors
