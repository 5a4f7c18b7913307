// The recorder process (`quadcosim record`): a vehicle's topics over DDS into an MCAP file, like
// `ros2 bag record`, until Ctrl-C or a duration.
#pragma once

#include <string>
#include <vector>

namespace quadcosim::hosts {

/// What to record, and for how long.
struct RecorderOptions {
  std::string out;                  ///< MCAP file (metadata.yaml is written beside it)
  std::string ns = "/drone";        ///< the vehicle's namespace
  std::vector<std::string> topics;  ///< subset of the vehicle's topics (default: all)
  double duration_s = -1.0;         ///< stop after this wall time [s] (default: Ctrl-C)
  std::string enclave = "/";        ///< DDS Security enclave (rcl --enclave)
};

/// Records as `o` says; the exit code of `record` (0, or 2 for a bad namespace or topic).
int run_recorder(const RecorderOptions& o);

}  // namespace quadcosim::hosts
