// A Python controller in a process of its own (isolation/child.hpp), the CLI's default for
// `controller: {python: ...}`: a controller that segfaults (a C extension), aborts, calls os._exit()
// or hangs in C ends only its process, and the run ends with a message naming the controller, the
// step and its time (exit 5), its outputs written up to the last finished tick. The parent loads the
// controller (so its parameters, outputs and errors at load are as in-process), then each instance
// forks a child that flies a copy of it and serves step, reset and the parameters over a socket pair.
// Values cross as their bytes: the same trajectory as in-process, bit for bit.
//
// A step with step_timeout_s > 0 is stopped inside Python by quadcosim.StepTimeout as in-process; one
// that does not stop (blocked in C) is given one more second, then its process is killed. Ctrl-C and
// SIGTERM end a wait at once (isolation::Interrupted). QUADCOSIM_PYTHON_IN_PROCESS=1 flies Python
// controllers in quadcosim's own process instead (faster; a crash then takes the run down).
#pragma once

#include <memory>

#include "control/controller.hpp"
#include "python/py_controller.hpp"

namespace quadcosim::embedded_python {

/// `prototype` flown in a child process. Takes the GIL to fork (the caller must not hold it).
std::unique_ptr<control::Controller> isolate_python_controller(std::shared_ptr<const python::PyController> prototype);

/// True unless QUADCOSIM_PYTHON_IN_PROCESS is set to 1.
bool python_controllers_isolated();

}  // namespace quadcosim::embedded_python
