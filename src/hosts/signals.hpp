// SIGINT/SIGTERM for long-running commands: the handler only sets a flag that loops poll.
#pragma once

#include <chrono>

namespace quadcosim::hosts {

/// Routes SIGINT and SIGTERM to stop_requested(), which is also what a wait on an FMU's process polls
/// (fmi::set_stop_check): a step that hangs there is given up and its process killed.
/// Also starts, once, a thread that ends the process with 130 when the command has not ended
/// kStopDeadlineS after the first stop request (a step stuck in code that never returns): Ctrl-C and
/// SIGTERM always end a command within about that.
void install_stop_handlers();
/// Seconds a command has after a stop request before the process is ended for it [s].
inline constexpr double kStopDeadlineS = 1.5;
/// True once SIGINT or SIGTERM arrived, or request_stop() was called.
bool stop_requested();
/// True once SIGINT or SIGTERM arrived (not for request_stop()): an isolated foreign step given up on
/// that signal is an interruption, not the foreign code's failure.
bool stop_signalled();
/// Asks the command's loops to stop, as a signal does (from any thread), without the deadline.
void request_stop();
/// Waits until a stop is requested or `deadline` passed; returns stop_requested(). Woken by
/// request_stop() and, once install_stop_handlers() ran, by SIGINT/SIGTERM (no polling).
bool wait_for_stop(std::chrono::steady_clock::time_point deadline);

}  // namespace quadcosim::hosts
