// Many vehicles, each a complete co-simulation of its own (PlantNode + ControllerNode on its own
// in-process bus, the same Simulation a single run uses, with its own lockstep driver), laid out on a
// grid, each with its own setpoint (sim/swarm_layout.hpp). The vehicles do not interact, so each
// one's trajectory is exactly the one its own single-vehicle Simulation would give (bit for bit),
// whatever the thread count or block length.
#pragma once

#include <cstdint>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "inproc/simulation.hpp"
#include "sim/swarm_layout.hpp"

namespace quadcosim::inproc {

using sim::SwarmLayout;
using sim::SwarmVehicle;

class Swarm {
 public:
  /// Builds N simulations (vehicle i from swarm_vehicle(..., i)). Throws like Simulation.
  Swarm(const SimulationConfig& simulation, const model::VehicleParams& vehicle, const model::State& initial,
        const control::ControllerConfig& controller, const std::vector<sim::ScheduledParameter>& schedule,
        const SwarmLayout& layout);

  /// Called after each tick's latch for recorded vehicles only (on the thread that owns the vehicle).
  using Recorder = std::function<void(int vehicle, const TickRecord&)>;

  /// Runs ticks 0..duration_ticks of every vehicle on `threads` threads (vehicles split in
  /// contiguous ranges). Each thread takes its vehicles through the run in blocks of `block_ticks`:
  /// within a block each vehicle runs its ticks back to back (its data stays in the cache), and at
  /// the end of a block all of the thread's vehicles are at the same tick. `recorded[i]` (when not
  /// empty) selects vehicles whose ticks go to `recorder`.
  /// Rethrows the first exception a vehicle raised (e.g. a refused scheduled parameter).
  void run(int threads, sim::Tick block_ticks, const std::vector<bool>& recorded = {}, const Recorder& recorder = {});

  /// The same for ticks first..last only (0 <= first, last <= duration_ticks); successive calls
  /// continue where the last one stopped (run() is run_ticks(0, duration_ticks, ...)).
  void run_ticks(sim::Tick first, sim::Tick last, int threads, sim::Tick block_ticks,
                 const std::vector<bool>& recorded = {}, const Recorder& recorder = {});

  int size() const { return static_cast<int>(vehicles_.size()); }
  const Simulation& vehicle(int i) const { return *vehicles_[static_cast<std::size_t>(i)]; }
  const std::string& vehicle_ns(int i) const { return namespaces_[static_cast<std::size_t>(i)]; }
  const SwarmVehicle& setup(int i) const { return setups_[static_cast<std::size_t>(i)]; }
  const SwarmLayout& layout() const { return layout_; }
  sim::Tick duration_ticks() const { return duration_ticks_; }

 private:
  SwarmLayout layout_;
  sim::Tick duration_ticks_;
  std::vector<SwarmVehicle> setups_;
  std::vector<std::string> namespaces_;
  std::vector<std::unique_ptr<Simulation>> vehicles_;
};

}  // namespace quadcosim::inproc
