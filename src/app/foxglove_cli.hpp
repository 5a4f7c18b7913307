// `--foxglove [ADDR:]PORT` and its companions on run, plant and controller: the flags (the serving is
// hosts/foxglove_serving.hpp).
#pragma once

#include <CLI/CLI.hpp>

#include "app/commands.hpp"
#include "hosts/foxglove_serving.hpp"

namespace quadcosim::app {

/// Adds --foxglove, --foxglove-linger and --foxglove-queue-kib to `cmd`; with `inprocess`, also
/// --foxglove-wait and --foxglove-pace (the in-process run's).
void add_foxglove_options(CLI::App& cmd, FoxgloveCliOptions& o, bool inprocess);

}  // namespace quadcosim::app
