// The recordings of a run as every host builds them: io/recording.hpp's (trajectory.csv, the series in
// memory, run.mcap) and the live view over Foxglove (hosts/foxglove_serving.hpp), which io/ cannot
// build (foxglove/ sits beside io/ and includes it), all sim::Recorders of one io::Recording.
#pragma once

#include <string>

#include "hosts/node_options.hpp"
#include "io/recording.hpp"
#include "sim/transport.hpp"

namespace quadcosim::hosts {

/// What a run records (io::RecordingOptions) and, with foxglove.listen set, serves live.
struct RecordingOptions : io::RecordingOptions {
  RecordingOptions() = default;
  /// `o` (e.g. io::RecordingOptions::for_run(scenario)), nothing served.
  explicit RecordingOptions(const io::RecordingOptions& o) : io::RecordingOptions(o) {}
  FoxgloveOptions foxglove;  ///< --foxglove and its options (listen "": not served)
  std::string who = "run";   ///< the node named in the live view's lines on stderr ("run", "plant", ...)
};

/// io::make_recording's recorders, then the Foxglove live view when `o.foxglove.listen` is set (tapped
/// through `bus`, which must outlive the recording; std::invalid_argument when it is asked without a
/// bus). Throws as io::make_recording and FoxgloveRecording do.
io::Recording make_recording(const RecordingOptions& o, sim::Transport* bus);

}  // namespace quadcosim::hosts
