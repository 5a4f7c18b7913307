// The swarm processes over DDS: `plant --vehicles N` and `controller --vehicles N` host N vehicles'
// nodes in one process each, lockstep only (swarm_nodes.cpp).
#pragma once

#include "hosts/node_options.hpp"
#include "io/scenario.hpp"

namespace quadcosim::hosts {

/// The plants of the swarm of `sc` (o.swarm: vehicles, namespace prefix, threads, the folder of
/// summary.json, vehicles.csv and the recorded vehicles); the exit code of `plant`.
int run_plant_swarm(const PlantProcessOptions& o, io::Scenario sc);

/// Their controllers; the exit code of `controller`.
int run_controller_swarm(const ControllerProcessOptions& o, io::Scenario sc);

}  // namespace quadcosim::hosts
