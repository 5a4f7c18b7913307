// Controllers written in Python in the CLI (docs/python.md). Built with Python (QUADCOSIM_BUILD_PYTHON,
// pybind11 and the Python headers found), the CLI embeds an interpreter that starts on first use only:
// a run of a C++ controller never starts it. Built without, the same calls say so (python_host_none.cpp).
#pragma once

#include <filesystem>
#include <functional>
#include <memory>
#include <string>

#include "control/controller.hpp"
#include "io/scenario_resolvers.hpp"
#include "model/vehicle_params.hpp"

namespace quadcosim::embedded_python {

/// True when this quadcosim was built with Python.
bool built_with_python();

/// What resolves a scenario's `controller: {python: "module:Class"}` (io::ScenarioResolvers::python):
/// make_python_controller's loader with Python; empty without (io's own error then names what is
/// missing). Cheap: no interpreter starts here.
io::PythonControllerFactory python_controller_factory();

/// The controller `spec` ("module:Class") names, for the vehicle: starts the interpreter on first use,
/// imports the module with `folder`, the current directory and PYTHONPATH on sys.path (and the
/// package quadcosim where it was built), instantiates the class. `what` names the option or key in
/// errors. Throws io::ConfigError for a bad spec, a module that does not import, a missing class,
/// and when this quadcosim was built without Python.
std::shared_ptr<const control::Controller> make_python_controller(const std::string& spec,
                                                                  const std::filesystem::path& folder,
                                                                  const model::VehicleParams& vehicle,
                                                                  const std::string& what);

/// The source file of the module of a Python controller `target` ("module:Class") loaded in this process
/// (for the run's provenance), or "" when none was loaded (or without Python).
std::string python_module_file(const std::string& target);

/// What a thread that calls Python controllers runs its loop in (sim::ControllerThread::ThreadHost):
/// the loop keeps one Python thread state for the thread's life, the GIL released. Empty without
/// Python.
std::function<void(const std::function<void()>&)> python_thread_host();

/// At the end of a command: flushes Python's sys.stdout and sys.stderr when the interpreter runs. The
/// interpreter is never finalized: a controller left behind in a call that never returns must not
/// meet a finalized interpreter.
void python_at_exit();

}  // namespace quadcosim::embedded_python
