// What an in-process co-simulation of one vehicle is set up with (inproc::Simulation runs it; a
// scenario file loads it, io/scenario.hpp), and what it reports per tick.
#pragma once

#include <string>

#include "control/parameters.hpp"
#include "sim/clock.hpp"
#include "sim/faults.hpp"
#include "sim/messages.hpp"
#include "sim/plant_node.hpp"

namespace quadcosim::sim {

struct SimulationConfig {
  PlantOptions plant;
  int controller_divider = 2;  ///< controller period = divider * plant period
  Tick duration_ticks = 1500;  ///< last recorded tick
  std::string ns = "/drone";
  FaultConfig faults;  ///< injected message loss and delay (in-process only; none by default)
};

/// One recorded tick.
struct TickRecord {
  Tick tick;
  double t_s;
  const model::State& state;
  const model::Vector4& applied_command;  ///< rotor command acting over [t_k, t_k+1) [rad/s]
  const msg::ControllerStatus& status;    ///< the controller's latest step, as published
};

}  // namespace quadcosim::sim
