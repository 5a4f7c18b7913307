// What `quadcosim margins` analyses (docs/margins.md): a scenario's controller after its schedule,
// its plant and the timing of its loops for the analytic margins, and the simulation the measured
// margins fly, with what each leaves out of the scenario said in notes.
#pragma once

#include <string>
#include <vector>

#include "analysis/hover_loops.hpp"
#include "analysis/measured_margins.hpp"
#include "control/controller_config.hpp"
#include "io/scenario_resolvers.hpp"
#include "model/vehicle_params.hpp"

namespace quadcosim::hosts {

/// The loops of a scenario's controller about hover, and how to measure them.
struct MarginsSetup {
  std::string source;  ///< the scenario path, or "defaults"
  model::VehicleParams plant;
  control::ControllerConfig controller;
  analysis::LoopTiming timing;
  std::vector<std::string> notes;  ///< what the linearisation leaves out, said once each
  /// What the measurement flies: the scenario's simulation with noise, wind, rotor faults and
  /// message drops left out (delays, latencies and sensor rates kept).
  analysis::HoverMeasurementSetup measured;
  std::vector<std::string> measured_notes;
};

/// The controller of the scenario at `path` (the defaults when empty; `controller_type`, when not
/// empty, replaces its controller.type) after its schedule, its plant and its timing. Throws
/// io::ConfigError (bad file) or std::invalid_argument (a refused scheduled change).
MarginsSetup margins_setup(const std::string& path, const std::string& controller_type,
                           const io::ScenarioResolvers& resolvers);

}  // namespace quadcosim::hosts
