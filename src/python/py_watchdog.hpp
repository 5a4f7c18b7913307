// The watchdog of Python controllers' step_timeout_s: one thread per process that raises StepTimeout in
// a step that overran its limit. A step costs it one clock read and two atomic stores; the thread polls
// the controllers that have a limit every tenth of the shortest one (1 ms to 50 ms), and sleeps while
// there are none. Internal to the Python controller (python/py_controller.hpp).
#pragma once

#include <atomic>
#include <cstdint>
#include <memory>

#include "python/py_controller.hpp"

namespace quadcosim::python {

struct PyController::Watch {
  std::atomic<std::int64_t> deadline_ns{0};  ///< steady clock; 0 while not in a step
  std::atomic<std::int64_t> timeout_ns{0};
  std::atomic<unsigned long> thread_id{0};  ///< the stepping thread (threading.get_ident())
  std::atomic<bool> fired{false};           ///< StepTimeout was raised into the current step
};

/// The steady clock [ns], as the watch's deadlines are written.
std::int64_t now_ns();

/// Watches `watch` from now on (until its controller lets it go), starting the thread at the first.
void add_to_watchdog(const std::shared_ptr<PyController::Watch>& watch);

}  // namespace quadcosim::python
