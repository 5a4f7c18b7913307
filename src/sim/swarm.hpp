// Many vehicles, each a complete co-simulation of its own (PlantNode + ControllerNode on its own
// in-process bus, the same Simulation a single run uses), laid out on a grid, each with its own
// setpoint. The vehicles do not interact, so each one's trajectory is exactly the one its own
// single-vehicle Simulation would give (bit for bit), whatever the thread count or block length.
//
// Vehicle i (0-based) of N:
//   - namespace  <ns_prefix><i>, i zero-padded to max(4, digits of N-1): /uav0000, /uav0001, ...
//   - grid cell  column i mod C, row i div C, with C = ceil(sqrt(N)) columns;
//   - offset_W   (column * spacing_m, row * spacing_m, (i mod altitude_layers) * layer_spacing_m);
//   - it starts at the scenario's initial position + (offset x, offset y, 0) and tracks the
//     scenario's setpoint + offset_W: x_des, y_des, z_des (initial and scheduled) shifted by it.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "sim/simulation.hpp"

namespace quadcosim::sim {

struct SwarmLayout {
  int vehicles = 16;               ///< N >= 1
  double spacing_m = 2.0;          ///< grid spacing in x and y [m], > 0
  int altitude_layers = 1;         ///< z_des cycles through this many layers, >= 1
  double layer_spacing_m = 1.0;    ///< height between layers [m], >= 0
  std::string ns_prefix = "/uav";  ///< namespaces are <prefix><index>
};

/// Namespace of vehicle `index` of `vehicles`: "/uav0007" (prefix + zero-padded index).
std::string vehicle_namespace(const std::string& prefix, int index, int vehicles);

/// Offset of vehicle `index` from the scenario's position and setpoint [m], world frame.
Eigen::Vector3d vehicle_offset_W(const SwarmLayout& layout, int index);

/// What one vehicle of the swarm runs: the scenario's settings shifted by its offset.
struct SwarmVehicle {
  SimulationConfig simulation;
  model::State initial;
  control::ControllerConfig controller;
  std::vector<ScheduledParameter> schedule;
};
SwarmVehicle swarm_vehicle(const SimulationConfig& simulation, const model::State& initial,
                           const control::ControllerConfig& controller, const std::vector<ScheduledParameter>& schedule,
                           const SwarmLayout& layout, int index);

class Swarm {
 public:
  /// Builds N simulations (vehicle i from swarm_vehicle(..., i)). Throws like Simulation.
  Swarm(const SimulationConfig& simulation, const model::VehicleParams& vehicle, const model::State& initial,
        const control::ControllerConfig& controller, const std::vector<ScheduledParameter>& schedule,
        const SwarmLayout& layout);

  /// Called after the tick's latch for recorded vehicles only (on the thread that owns the vehicle).
  using Recorder = std::function<void(int vehicle, const TickRecord&)>;

  /// Asked on the calling thread after each of its blocks, with the last tick that block flew: true
  /// stops the run (every thread stops at the end of its current block).
  using StopCheck = std::function<bool(Tick last_tick)>;

  /// Runs ticks 0..duration_ticks of every vehicle on `threads` threads (vehicles split in
  /// contiguous ranges; the calling thread flies the first range). Each thread takes its vehicles
  /// through the run in blocks of `block_ticks`: within a block each vehicle runs its ticks back to back
  /// (its data stays in the cache), and at the end of a block all of the thread's vehicles are at the
  /// same tick. `recorded[i]` (when not empty) selects vehicles whose ticks go to `recorder`. Every
  /// thread lives until the run ends (what a vehicle starts on its thread, such as a controller's own
  /// process, stays). Returns false when `stop` stopped the run. Rethrows the first exception a vehicle
  /// raised (e.g. a refused scheduled parameter).
  bool run(int threads, Tick block_ticks, const std::vector<bool>& recorded = {}, const Recorder& recorder = {},
           const StopCheck& stop = {});

  /// The same for ticks first..last only (0 <= first, last <= duration_ticks); successive calls
  /// continue where the last one stopped (run() is run_ticks(0, duration_ticks, ...)).
  bool run_ticks(Tick first, Tick last, int threads, Tick block_ticks, const std::vector<bool>& recorded = {},
                 const Recorder& recorder = {}, const StopCheck& stop = {});

  int size() const { return static_cast<int>(vehicles_.size()); }
  const Simulation& vehicle(int i) const { return *vehicles_[static_cast<std::size_t>(i)]; }
  const std::string& vehicle_ns(int i) const { return namespaces_[static_cast<std::size_t>(i)]; }
  const SwarmVehicle& setup(int i) const { return setups_[static_cast<std::size_t>(i)]; }
  const SwarmLayout& layout() const { return layout_; }
  Tick duration_ticks() const { return duration_ticks_; }

 private:
  SwarmLayout layout_;
  Tick duration_ticks_;
  std::vector<SwarmVehicle> setups_;
  std::vector<std::string> namespaces_;
  std::vector<std::unique_ptr<Simulation>> vehicles_;
};

}  // namespace quadcosim::sim
