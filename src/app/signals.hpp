// SIGINT/SIGTERM for long-running commands: the handler only sets a flag that loops poll.
#pragma once

namespace quadcosim::app {

/// Routes SIGINT and SIGTERM to stop_requested().
void install_stop_handlers();
/// True once SIGINT or SIGTERM arrived.
bool stop_requested();

}  // namespace quadcosim::app
