// A vehicle's extra sensors stepping with its plant, with no bus: each sensor the scenario configures
// (sensors/registry.hpp) samples its model on the plant ticks k with k % divider == 0, measuring the
// truth of tick max(k - latency, 0). Every host steps the same suite: the plant's core (sim::PlantCore,
// which the plant node steps and puts on the wire through sim/sensor_channels.hpp, and Batch's lean
// vehicles step directly) and the plant FMU.
//
// Determinism: a tick's samples are drawn once; stepping the same tick again (a lockstep repeat)
// leaves them as they are. Each sensor draws from its own stream, model::stream_seed(seed, vehicle,
// sensor name), so adding one never changes the numbers of another or of the paper's sensors.
#pragma once

#include <cstdint>
#include <optional>
#include <string_view>
#include <tuple>
#include <vector>

#include "model/quadrotor.hpp"
#include "sensors/registry.hpp"

namespace quadcosim::sensors {

/// One configured sensor: its model and its newest sample.
template <class Kind>
struct Slot {
  typename Kind::Model model;
  typename Kind::Sample sample;  ///< the newest sample
  std::int64_t tick = -1;        ///< the plant tick that published it; -1 before the first
};

class Suite {
 public:
  Suite() = default;
  /// The sensors `set` configures, their noise streams named by `vehicle` ("/drone"), on a plant of
  /// period `period_ns`.
  Suite(const SensorSet& set, std::uint64_t seed, std::string_view vehicle, std::int64_t period_ns);

  bool empty() const { return history_.empty(); }

  /// Tick k's truth `y` (ticks in order; a tick again changes nothing): samples each sensor due at k.
  /// Returns whether any was due.
  bool step(std::int64_t k, const model::Outputs& y);

  /// Kind's slot, or null when the suite does not carry it.
  template <class Kind>
  const Slot<Kind>* slot() const {
    const auto& s = std::get<std::optional<Slot<Kind>>>(slots_);
    return s ? &*s : nullptr;
  }
  /// Kind published a sample at tick k.
  template <class Kind>
  bool due(std::int64_t k) const {
    const Slot<Kind>* s = slot<Kind>();
    return s && s->tick == k;
  }

 private:
  template <class... K>
  static std::tuple<std::optional<Slot<K>>...> slots_of(std::tuple<K...>*);
  using Slots = decltype(slots_of(static_cast<Kinds*>(nullptr)));

  Slots slots_;
  std::vector<model::Outputs> history_;  ///< ring of true outputs, max latency + 1 deep; empty: no sensor
  std::int64_t period_ns_ = 0;
  std::int64_t last_tick_ = -1;
};

}  // namespace quadcosim::sensors
