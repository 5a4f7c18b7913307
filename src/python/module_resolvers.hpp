// The resolvers of the Python module's scenarios (io/scenario_resolvers.hpp).
#pragma once

#include "io/scenario_resolvers.hpp"

namespace quadcosim::python {

/// What the module's scenarios are loaded with: Python classes imported by this interpreter
/// (load_python_controller, their files found by loaded_module_file) and FMUs through the one loader
/// (hosts::FmuLoader) the module holds from its first use until the interpreter unloads it.
const io::ScenarioResolvers& module_resolvers();

}  // namespace quadcosim::python
