// python/py_runtime.hpp: the interpreter helpers and the process-wide Python objects.
#include "python/py_runtime.hpp"

#include <fmt/format.h>
#include <pybind11/eval.h>

namespace py = pybind11;

namespace quadcosim::python {

/// True while Python objects may be released or called: the interpreter is up and not finalising.
bool python_alive() {
  if (!Py_IsInitialized()) return false;
#if PY_VERSION_HEX >= 0x030D0000
  return !Py_IsFinalizing();
#else
  return !_Py_IsFinalizing();
#endif
}

/// The pending Python exception, normalised, with its traceback attached; clears it.
py::object fetch_error() {
  PyObject *type = nullptr, *value = nullptr, *trace = nullptr;
  PyErr_Fetch(&type, &value, &trace);
  PyErr_NormalizeException(&type, &value, &trace);
  if (value && trace) PyException_SetTraceback(value, trace);
  Py_XDECREF(type);
  Py_XDECREF(trace);
  if (!value) return py::none();
  return py::reinterpret_steal<py::object>(value);
}

/// "ZeroDivisionError: division by zero (at ctrl.py:12)": the exception's type, text and innermost frame.
std::string describe_error(const py::handle& error) {
  if (!error || error.is_none()) return "unknown error";
  std::string text;
  try {
    text = py::str(py::type::handle_of(error).attr("__name__")).cast<std::string>();
    const std::string message = py::str(error).cast<std::string>();
    if (!message.empty()) text += ": " + message;
    py::object tb = error.attr("__traceback__");
    if (!tb.is_none()) {
      while (!tb.attr("tb_next").is_none()) tb = tb.attr("tb_next");
      const py::object code = tb.attr("tb_frame").attr("f_code");
      text += fmt::format(" (at {}:{} in {})", py::str(code.attr("co_filename")).cast<std::string>(),
                          tb.attr("tb_lineno").cast<long>(), py::str(code.attr("co_name")).cast<std::string>());
    }
  } catch (const py::error_already_set&) {
    if (text.empty()) text = "an exception that cannot be shown";
  }
  return text;
}

/// "a str ('abc')": how a returned value appears in errors.
std::string describe_value(const py::handle& v) {
  std::string repr;
  try {
    repr = py::repr(v).cast<std::string>();
  } catch (const py::error_already_set&) {
    repr = "?";
  }
  if (repr.size() > 60) repr = repr.substr(0, 57) + "...";
  return fmt::format("{} ({})", py::str(py::type::handle_of(v).attr("__name__")).cast<std::string>(), repr);
}

bool is_real_number(const py::handle& v) {
  if (PyFloat_Check(v.ptr()) || (PyLong_Check(v.ptr()) && !PyBool_Check(v.ptr()))) return true;
  if (py::isinstance<py::array>(v)) {  // a 0-d numeric array (np.clip of a scalar, a reduction)
    const auto a = py::reinterpret_borrow<py::array>(v);
    const char kind = a.dtype().kind();
    return a.ndim() == 0 && (kind == 'f' || kind == 'i' || kind == 'u');
  }
  // numpy scalars and other numbers with __float__, but not strings, bools or complex numbers.
  return !PyBool_Check(v.ptr()) && !PyUnicode_Check(v.ptr()) && !PyBytes_Check(v.ptr()) && !PyComplex_Check(v.ptr()) &&
         py::hasattr(v, "__float__") && !py::hasattr(v, "__len__");
}

namespace {

const char* const kClassesSource = R"PY(
class Observation:
    """What a Python controller observes at one step (quadcosim's control::Observation).

    Reused from step to step (the arrays are rewritten in place): copy what you keep.
    p, v: position [m] and velocity [m/s] in the world frame (numpy float64, 3); q: attitude body -> world
    (w, x, y, z); w: body rates [rad/s]; f: specific force (accelerometer) [m/s^2] in the body frame;
    roll, pitch, yaw: Z-Y-X angles of q [rad]; age: age of the oldest input [s]; t: the step's time [s].

    The extra sensors (docs/sensors.md): magnetometer, barometer, gnss, each a SensorReading with the
    newest sample the controller node took in, or None when the vehicle does not carry that sensor
    (the scenario's sensors: section). age covers p, v, q, w, f only; each reading has its own stamp t.
    """

    __module__ = "quadcosim"

    def __repr__(self):
        return "Observation(" + ", ".join(f"{k}={v!r}" for k, v in self.__dict__.items()) + ")"


class SensorReading:
    """The newest sample of one extra sensor a Python controller observes (obs.magnetometer,
    obs.barometer, obs.gnss; docs/sensors.md), reused from step to step like the Observation.

    One attribute per column of the sample, in SI units: a vector a numpy float64 array (3, read-only,
    rewritten in place), a number a float, a flag a bool. magnetometer: field (3) [T], body frame;
    barometer: pressure [Pa], altitude [m] (ISA pressure altitude above mean sea level); gnss: fix (bool),
    latitude_deg, longitude_deg [deg], altitude_m [m] (above the WGS-84 ellipsoid), v (3) [m/s], world
    frame (ENU); without a fix the GNSS numbers are NaN. t: the sample's stamp [s] (the simulated time of
    the tick that published it; with the sensor's latency_ticks it measures the truth that many ticks
    earlier), None before the first sample (then every number is NaN and a flag False).
    """

    __module__ = "quadcosim"

    def __repr__(self):
        return "SensorReading(" + ", ".join(f"{k}={v!r}" for k, v in self.__dict__.items()) + ")"


class Reference:
    """What the vehicle is asked to do at one step (quadcosim's control::Reference).

    Reused from step to step: copy what you keep. mode: "attitude" (roll, pitch, yaw setpoints and
    p[2] as the altitude to hold) or "position"; p, v, a, j: position [m] and its first three
    derivatives in the world frame (numpy float64, 3); yaw [rad], yaw_rate [rad/s]; roll, pitch [rad]
    (attitude mode).
    """

    __module__ = "quadcosim"

    def __repr__(self):
        return "Reference(" + ", ".join(f"{k}={v!r}" for k, v in self.__dict__.items()) + ")"


class StepTimeout(BaseException):
    """Raised inside a Python controller's step that ran longer than its step_timeout_s.

    A BaseException, like KeyboardInterrupt, so that `except Exception:` does not swallow it.
    """

    __module__ = "quadcosim"
)PY";

}  // namespace

Globals& globals() {
  static Globals* g = [] {
    auto* n = new Globals;
    py::dict scope;
    scope["__builtins__"] = py::module_::import("builtins");
    scope["__name__"] = "quadcosim";
    py::exec(kClassesSource, scope);
    n->observation_class = scope["Observation"];
    n->reference_class = scope["Reference"];
    n->sensor_reading_class = scope["SensorReading"];
    n->step_timeout = scope["StepTimeout"];
    n->deepcopy = py::module_::import("copy").attr("deepcopy");
    n->signature = py::module_::import("inspect").attr("signature");
    auto intern = [](const char* s) { return PyUnicode_InternFromString(s); };
    n->p = intern("p");
    n->v = intern("v");
    n->q = intern("q");
    n->w = intern("w");
    n->f = intern("f");
    n->a = intern("a");
    n->j = intern("j");
    n->roll = intern("roll");
    n->pitch = intern("pitch");
    n->yaw = intern("yaw");
    n->yaw_rate = intern("yaw_rate");
    n->age = intern("age");
    n->t = intern("t");
    n->mode = intern("mode");
    n->attitude = intern("attitude");
    n->position = intern("position");
    return n;
  }();
  return *g;
}

void set_item(const py::object& dict, PyObject* key, PyObject* value_new_ref) {
  PyDict_SetItem(dict.ptr(), key, value_new_ref);
  Py_DECREF(value_new_ref);
}

void set_float(const py::object& dict, PyObject* key, double value) { set_item(dict, key, PyFloat_FromDouble(value)); }

void set_borrowed(const py::object& dict, PyObject* key, PyObject* value) { PyDict_SetItem(dict.ptr(), key, value); }

/// A read-only numpy view of n doubles of `buffer` from `at`: C++ writes the memory, the controller reads it.
py::object read_only_view(const py::array_t<double>& buffer, int at, int n) {
  py::object a = buffer[py::slice(at, at + n, 1)];
  a.attr("flags").attr("writeable") = false;
  return a;
}

}  // namespace quadcosim::python
