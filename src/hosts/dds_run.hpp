// `quadcosim run --transport dds` (docs/cosimulation.md): plant and controller as two child processes
// of this executable over DDS, in lockstep (or real time); the plant records. Their command lines
// are made here from plain options, a fresh pairing token keeps them to each other, and with a
// keystore both run secured, each in its own enclave.
#pragma once

#include <string>

#include "hosts/foxglove_serving.hpp"

namespace quadcosim::hosts {

struct DdsRunOptions {
  std::string scenario;
  std::string controller;    ///< replaces the scenario's controller.type ("" keeps it)
  bool realtime = false;     ///< real time instead of lockstep
  double rate_factor = 1.0;  ///< real time: k times faster than the wall clock
  double timeout_s = 10.0;   ///< lockstep wait for one command before the policy applies
  bool pin = false;          ///< plant and controller each on its own CPU
  /// Run secured (Enforce) with this SROS2 keystore; created when missing, as are the enclaves
  /// /quadcosim/plant and /quadcosim/controller ("" = as the ROS_SECURITY_* environment says).
  std::string keystore;
  FoxgloveOptions foxglove;  ///< served by the plant (it has every topic and the simulated time)
};

/// Plant and controller as two child processes over DDS; the plant writes `csv_path` and run.mcap
/// beside it. Both are ended on every path (ChildProcess), also on Ctrl-C. Returns the exit code
/// (hosts/exit_code.hpp): the plant's, or the controller's when it failed.
int run_over_dds(const DdsRunOptions& opt, const std::string& csv_path);

}  // namespace quadcosim::hosts
