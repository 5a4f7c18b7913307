// The plant process over DDS (`quadcosim plant`, one vehicle): the plant node as a long-running
// process, in lockstep (deterministic, as fast as plant and controller can go) or in real time (paced
// by the wall clock), recording what it was asked to. `--vehicles N` is swarm_nodes.hpp.
#pragma once

#include "hosts/node_options.hpp"
#include "io/scenario.hpp"

namespace quadcosim::hosts {

/// Runs the plant of `sc` (the scenario as the options changed it; start_node_process) as `o` says,
/// until the last tick, a timeout or a stop request: pairs with the controller, drives the ticks,
/// records the trajectory CSV and MCAP, reports on stderr. Returns the exit code of `plant`
/// (docs/cosimulation.md): 0, 2 a refused scheduled change, 4 no controller (or one whose answers cannot
/// be matched to ticks), 130 interrupted.
int run_plant_process(const PlantProcessOptions& o, io::Scenario sc);

}  // namespace quadcosim::hosts
