// The controller process over DDS (`quadcosim controller`, one vehicle): the controller node as a
// long-running process, stepping once per complete sensor sample in lockstep (where the samples are
// delivered), or on a wall-clock timer in real time; its ROS 2 parameter services; live serving.
// `--vehicles N` is swarm_nodes.hpp.
#pragma once

#include "hosts/node_options.hpp"
#include "io/scenario.hpp"
#include "sim/controller_thread.hpp"

namespace quadcosim::hosts {

/// Runs the controller of `sc` (the scenario with the controller to fly: start_node_process, then the
/// front end's --params, --fmu or --python) as `o` says, until a stop request. A controller that wants
/// a thread of its own runs its loop in `thread_host` (a Python controller's: the interpreter's thread
/// state; empty: a plain thread). Returns 0 (also when a signal ended it); throws
/// sim::ControllerFailure when the controller failed and the node stopped for it.
int run_controller_process(const ControllerProcessOptions& o, io::Scenario sc,
                           sim::ControllerThread::ThreadHost thread_host);

}  // namespace quadcosim::hosts
