// SIGINT/SIGTERM for long-running commands: the handler only sets a flag that loops poll.
#pragma once

namespace quadcosim::app {

/// Routes SIGINT and SIGTERM to stop_requested().
void install_stop_handlers();
/// True once SIGINT or SIGTERM arrived, or request_stop() was called.
bool stop_requested();
/// Asks the command's loops to stop, as a signal does (from any thread).
void request_stop();

}  // namespace quadcosim::app
