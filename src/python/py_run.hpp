// A run from Python (quadcosim.run's compiled part, _run): flown, recorded and judged in process by the
// code `quadcosim run` uses (hosts/inprocess_run.hpp), so it writes the same bytes as the CLI.
#pragma once

#include <pybind11/pybind11.h>

namespace quadcosim::python {

/// Adds _run to the module.
void bind_run(pybind11::module_& m);

}  // namespace quadcosim::python
