// What the Python controller's source files (python/py_controller*.cpp, py_watchdog.cpp,
// py_sensor_views.cpp) share about the interpreter: whether it may be called, its pending exception and
// how errors show a Python value, the process-wide Python objects (the Observation, Reference,
// SensorReading and StepTimeout classes, interned attribute names), and the dict and array helpers the
// step's objects are filled with. Internal to the Python controller.
#pragma once

#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>

#include <string>

namespace quadcosim::python {

/// True while Python objects may be released or called: the interpreter is up and not finalising.
bool python_alive();

/// The pending Python exception, normalised, with its traceback attached; clears it.
pybind11::object fetch_error();

/// "ZeroDivisionError: division by zero (at ctrl.py:12)": the exception's type, text and innermost frame.
std::string describe_error(const pybind11::handle& error);

/// "a str ('abc')": how a returned value appears in errors.
std::string describe_value(const pybind11::handle& v);

/// A Python float or int (not a bool), a 0-d numeric array, or another number with __float__.
bool is_real_number(const pybind11::handle& v);

/// Process-wide Python objects, made once under the GIL and kept for the process's life (never
/// released: they may be needed until the interpreter finalises).
struct Globals {
  pybind11::object observation_class, reference_class, sensor_reading_class, step_timeout;
  pybind11::object deepcopy, signature;
  // Interned attribute names.
  PyObject *p, *v, *q, *w, *f, *a, *j, *roll, *pitch, *yaw, *yaw_rate, *age, *t, *mode;
  PyObject *attitude, *position;
};

/// The process's Globals (made at the first call; take the GIL).
Globals& globals();

/// dict[key] = value, taking over the new reference `value_new_ref`.
void set_item(const pybind11::object& dict, PyObject* key, PyObject* value_new_ref);
/// dict[key] = float(value).
void set_float(const pybind11::object& dict, PyObject* key, double value);
/// dict[key] = value (borrowed).
void set_borrowed(const pybind11::object& dict, PyObject* key, PyObject* value);

/// A read-only numpy view of n doubles of `buffer` from `at`: C++ writes the memory, the controller reads it.
pybind11::object read_only_view(const pybind11::array_t<double>& buffer, int at, int n);

}  // namespace quadcosim::python
