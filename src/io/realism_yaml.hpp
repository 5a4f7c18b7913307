// The scenario keys of the realism models (docs/scenarios.md, "Realism"): `seed`, `sensors`,
// `environment`, `faults`, `vehicle.aero` and `analysis.hold`. Every reader throws ConfigError
// naming file, key and value.
#pragma once

#include "io/scenario.hpp"
#include "io/yaml_reader.hpp"

namespace quadcosim::io {

/// Top-level `seed`, `sensors`, `environment`, `faults` into sc.simulation.plant.realism. Needs the
/// simulation section read first (rates and duration).
void read_realism(YamlSection& root, Scenario& sc);

/// Top-level `inner_loops`: the gains of the inner loops that fly commands above rotor speeds
/// (control/inner_loops.hpp; keys rate_bandwidth, attitude_bandwidth, velocity_bandwidth [rad/s],
/// max_tilt [rad]; defaults InnerLoopParams::for_vehicle), checked for the vehicle and the plant
/// period. Needs the vehicle and simulation sections read first. Called by read_realism.
void read_inner_loops(YamlSection& root, Scenario& sc);

/// `analysis.hold`: the position-hold criterion.
HoldSpec read_hold(YamlSection& s, double duration_s);

}  // namespace quadcosim::io
