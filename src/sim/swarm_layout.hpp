// How a swarm's vehicles are set up (inproc::Swarm in-process, `plant/controller --vehicles N` over
// DDS): each one the scenario's vehicle, laid out on a grid, with its own setpoint.
//
// Vehicle i (0-based) of N:
//   - namespace  <ns_prefix><i>, i zero-padded to max(4, digits of N-1): /uav0000, /uav0001, ...
//   - grid cell  column i mod C, row i div C, with C = ceil(sqrt(N)) columns;
//   - offset_W   (column * spacing_m, row * spacing_m, (i mod altitude_layers) * layer_spacing_m);
//   - it starts at the scenario's initial position + (offset x, offset y, 0) and tracks the
//     scenario's setpoint + offset_W: x_des, y_des, z_des (initial and scheduled) shifted by it.
#pragma once

#include <Eigen/Core>
#include <string>
#include <vector>

#include "control/parameters.hpp"
#include "model/quadrotor.hpp"
#include "sim/parameter_schedule.hpp"
#include "sim/simulation_config.hpp"

namespace quadcosim::sim {

struct SwarmLayout {
  int vehicles = 16;              ///< N >= 1
  double spacing_m = 2.0;         ///< grid spacing in x and y [m], > 0
  int altitude_layers = 1;        ///< z_des cycles through this many layers, >= 1
  double layer_spacing_m = 1.0;   ///< height between layers [m], >= 0
  std::string ns_prefix = "/uav"; ///< namespaces are <prefix><index>
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
                           const control::ControllerConfig& controller,
                           const std::vector<ScheduledParameter>& schedule, const SwarmLayout& layout,
                           int index);

}  // namespace quadcosim::sim
