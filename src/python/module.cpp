// The Python module quadcosim (its compiled part, quadcosim._quadcosim; the package's __init__.py adds
// load_scenario(), run() and RunResult on top). Scenarios are read and validated by io::load_scenario,
// runs recorded and judged by the code `quadcosim run` uses (hosts/inprocess_run.hpp), so a run from
// Python writes the same bytes as the CLI. The GIL is released around all C++ simulation work.
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>

#include "batch.hpp"
#include "io/scenario.hpp"
#include "python/py_controller.hpp"
#include "python/py_run.hpp"
#include "python/py_scenario.hpp"
#include "python/py_simulation.hpp"

namespace py = pybind11;

PYBIND11_MODULE(_quadcosim, m) {
  using namespace quadcosim;
  using namespace quadcosim::python;
  m.doc() = "quadcosim's compiled core; use the package quadcosim (load_scenario, run, Simulation).";
  // pybind11's numpy API is looked up once, in a function-local static whose initialiser imports numpy
  // and lets the GIL go: done first by two Python threads whose controllers step at once, that would
  // deadlock (one in the static's guard waiting for the GIL, the other holding it). Done here, once.
  { const py::array_t<double> warm(1); }

  py::register_exception<io::ConfigError>(m, "ConfigError", PyExc_ValueError);
  // A Python controller's failure: quadcosim.ControllerError (a RuntimeError) with the controller's own
  // exception as __cause__; a KeyboardInterrupt (or SystemExit) inside a step passes as it is.
  static auto* controller_error = new py::object(py::reinterpret_steal<py::object>(
      PyErr_NewExceptionWithDoc("quadcosim.ControllerError",
                                "A Python controller failed: its step raised, returned what cannot be commanded "
                                "(wrong shape, not numbers, not finite) or overran step_timeout_s. The message "
                                "names the controller, the step and its time; __cause__ is the Python exception.",
                                PyExc_RuntimeError, nullptr)));
  m.attr("ControllerError") = *controller_error;
  m.attr("StepTimeout") = step_timeout_type();
  m.attr("Observation") = observation_class();
  m.attr("Reference") = reference_class();
  m.attr("SensorReading") = sensor_reading_class();
  py::register_exception_translator([](std::exception_ptr p) {
    try {
      if (p) std::rethrow_exception(p);
    } catch (const ControllerError& e) {
      py::object cause = e.python_error();
      if (e.interrupt()) {
        PyErr_SetObject(reinterpret_cast<PyObject*>(Py_TYPE(cause.ptr())), cause.ptr());
        return;
      }
      py::object error = (*controller_error)(e.what());
      if (!cause.is_none()) PyException_SetCause(error.ptr(), cause.release().ptr());
      PyErr_SetObject(controller_error->ptr(), error.ptr());
    }
  });

  bind_scenario(m);
  bind_run(m);
  bind_simulation(m);
  bind_batch(m);
}
