// quadcosim.Batch's compiled part (_quadcosim._Batch): N vehicles of one scenario stepped together,
// their state and sensor readings as (N, k) arrays filled by C++, the GIL released while stepping.
#pragma once

#include <pybind11/pybind11.h>

namespace quadcosim::python {

/// Adds _Batch and its helpers to the module.
void bind_batch(pybind11::module_& m);

}  // namespace quadcosim::python
