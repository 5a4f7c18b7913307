// quadcosim.Simulation: one vehicle of a scenario stepped one control period at a time from Python,
// the plant and the controller in lockstep as in quadcosim.run() (sim::Simulation), the GIL released
// while stepping.
#pragma once

#include <pybind11/pybind11.h>

namespace quadcosim::python {

/// Adds Simulation to the module.
void bind_simulation(pybind11::module_& m);

}  // namespace quadcosim::python
