// python/py_controller.hpp: PyController::step, the call into Python and the reading of what it returned.
#include <fmt/format.h>
#include <fmt/ranges.h>
#include <pybind11/numpy.h>

#include <cmath>
#include <string>

#include "python/py_controller.hpp"
#include "python/py_controller_parts.hpp"
#include "python/py_runtime.hpp"
#include "python/py_watchdog.hpp"

namespace py = pybind11;

namespace quadcosim::python {

void PyController::fail_step(const std::string& what, double t, py::object cause) {
  // A failed step counts too: a node that flies on (--on-controller-error safety) names each failure
  // by its own step and time, and the next call is the next step.
  const long long n = steps_++;
  throw ControllerError(fmt::format("{}.step at step {} (t = {:g} s): {}", shared_->name, n, t, what),
                        std::move(cause));
}

void PyController::step(const control::Observation& o, const control::Reference& r, double dt_s,
                        control::ControllerOutput& out) {
  const double t = static_cast<double>(steps_) * dt_s;
  py::gil_scoped_acquire gil;
  if (!call_) prepare_call();
  Call& c = *call_;
  const Globals& g = globals();
  if (carried_kinds(o.sensors) != c.sensors.carried) prepare_sensors(c.sensors, c.obs_dict, o.sensors);
  write_sensors(c.sensors, o.sensors);
  double* d = c.data;
  const auto copy3 = [](double* to, const Eigen::Vector3d& v) {
    to[0] = v.x();
    to[1] = v.y();
    to[2] = v.z();
  };
  copy3(d + kObsP, o.p_W);
  copy3(d + kObsV, o.v_W);
  d[kObsQ] = o.q_WB.w();
  d[kObsQ + 1] = o.q_WB.x();
  d[kObsQ + 2] = o.q_WB.y();
  d[kObsQ + 3] = o.q_WB.z();
  copy3(d + kObsW, o.w_B);
  copy3(d + kObsF, o.specific_force_B);
  copy3(d + kRefP, r.p_W);
  copy3(d + kRefV, r.v_W);
  copy3(d + kRefA, r.a_W);
  copy3(d + kRefJ, r.j_W);
  set_float(c.obs_dict, g.roll, o.roll_rad);
  set_float(c.obs_dict, g.pitch, o.pitch_rad);
  set_float(c.obs_dict, g.yaw, o.yaw_rad);
  set_float(c.obs_dict, g.age, o.age_s);
  set_float(c.obs_dict, g.t, t);
  set_float(c.ref_dict, g.yaw, r.yaw_rad);
  set_float(c.ref_dict, g.yaw_rate, r.yaw_rate_rad_s);
  set_float(c.ref_dict, g.roll, r.roll_rad);
  set_float(c.ref_dict, g.pitch, r.pitch_rad);
  if (const int mode = static_cast<int>(r.mode); mode != c.mode) {
    PyDict_SetItem(c.ref_dict.ptr(), g.mode, r.mode == control::Mode::kPosition ? g.position : g.attitude);
    c.mode = mode;
  }
  if (dt_s != c.dt_value) {
    c.dt = py::float_(dt_s);
    c.dt_value = dt_s;
  }

  // The call, watched when it has a time limit.
  const bool watched = step_timeout_s_ > 0.0;
  if (watched) {
    if (!watch_) {
      watch_ = std::make_shared<Watch>();
      watch_->timeout_ns.store(static_cast<std::int64_t>(step_timeout_s_ * 1e9));
      add_to_watchdog(watch_);
    }
    watch_->thread_id.store(PyThread_get_thread_ident());
    watch_->fired.store(false);
    watch_->deadline_ns.store(now_ns() + static_cast<std::int64_t>(step_timeout_s_ * 1e9), std::memory_order_release);
  }
  PyObject* args[] = {c.obs.ptr(), c.ref.ptr(), c.dt.ptr()};
#if PY_VERSION_HEX >= 0x03090000
  PyObject* raw = PyObject_Vectorcall(c.step.ptr(), args, 3, nullptr);
#else
  PyObject* raw = PyObject_CallFunctionObjArgs(c.step.ptr(), args[0], args[1], args[2], nullptr);
#endif
  if (watched) {
    watch_->deadline_ns.store(0, std::memory_order_release);  // still under the GIL: the watchdog sees it
    if (watch_->fired.load()) {
      // A StepTimeout raised but not yet delivered (the step returned from a C call without running
      // more bytecode) must not fire later, outside the step.
      PyThreadState_SetAsyncExc(PyThread_get_thread_ident(), nullptr);
      py::object error = raw ? py::object(py::none()) : fetch_error();
      Py_XDECREF(raw);
      fail_step(fmt::format("did not return within step_timeout_s = {:g} s{}", step_timeout_s_,
                            error.is_none() ? "" : " (stopped by quadcosim.StepTimeout)"),
                t, error);
    }
  }
  if (!raw) {
    py::object error = fetch_error();
    fail_step("raised " + describe_error(error), t, error);
  }
  const py::object result = py::reinterpret_steal<py::object>(raw);

  // omega, or (omega, outputs).
  py::handle omega = result;
  py::handle figures;
  if (PyTuple_Check(raw) && PyTuple_GET_SIZE(raw) == 2 && !is_real_number(PyTuple_GET_ITEM(raw, 0))) {
    omega = PyTuple_GET_ITEM(raw, 0);
    figures = PyTuple_GET_ITEM(raw, 1);
  }
  const auto read = [&](py::handle values, std::size_t n, const char* what, double* into) {
    if (values.is_none()) {
      fail_step(fmt::format("returned None, expected {}", what), t);
    }
    if (PyUnicode_Check(values.ptr()) || PyBytes_Check(values.ptr()) || is_real_number(values)) {
      fail_step(fmt::format("returned {}, expected {}", describe_value(values), what), t);
    }
    if (py::isinstance<py::array>(values)) {
      const auto a = py::reinterpret_borrow<py::array>(values);
      const char kind = a.dtype().kind();
      if (a.ndim() != 1 || static_cast<std::size_t>(a.shape(0)) != n) {
        std::string shape = "(";
        for (py::ssize_t i = 0; i < a.ndim(); ++i) shape += fmt::format("{}{}", i ? ", " : "", a.shape(i));
        shape += a.ndim() == 1 ? ",)" : ")";
        fail_step(fmt::format("returned shape {}, expected {}", shape, what), t);
      }
      if (kind != 'f' && kind != 'i' && kind != 'u') {
        fail_step(fmt::format("returned an array of dtype {}, expected {} (real numbers)",
                              py::str(a.dtype()).cast<std::string>(), what),
                  t);
      }
      const auto f = py::array_t<double, py::array::forcecast>::ensure(a);
      for (std::size_t i = 0; i < n; ++i) into[i] = f.at(static_cast<py::ssize_t>(i));
      return;
    }
    if (!PySequence_Check(values.ptr())) {  // not a dict, set or iterator: an order is needed
      fail_step(fmt::format("returned {}, expected {}", describe_value(values), what), t);
    }
    PyObject* seq = PySequence_Fast(values.ptr(), "");
    if (!seq) {
      PyErr_Clear();
      fail_step(fmt::format("returned {}, expected {}", describe_value(values), what), t);
    }
    const auto owned = py::reinterpret_steal<py::object>(seq);
    const std::size_t size = static_cast<std::size_t>(PySequence_Fast_GET_SIZE(seq));
    if (size != n) fail_step(fmt::format("returned {} values, expected {}", size, what), t);
    PyObject** items = PySequence_Fast_ITEMS(seq);
    for (std::size_t i = 0; i < n; ++i) {
      PyObject* item = items[i];
      if (PyFloat_Check(item)) {
        into[i] = PyFloat_AS_DOUBLE(item);
        continue;
      }
      if (!is_real_number(item)) {
        fail_step(fmt::format("returned {} as entry {}, expected {} (real numbers)", describe_value(item), i, what), t);
      }
      into[i] = PyFloat_AsDouble(item);
      if (into[i] == -1.0 && PyErr_Occurred()) {
        py::object error = fetch_error();
        fail_step(fmt::format("entry {} is not a number: {}", i, describe_error(error)), t, error);
      }
    }
  };
  // One speed per rotor of the vehicle (4 for a quadrotor).
  const int rotors = model_.rotor_count();
  double omega_values[model::kMaxRotors];
  const std::string speeds = fmt::format("{} rotor speeds [rad/s]", rotors);
  read(omega, static_cast<std::size_t>(rotors), speeds.c_str(), omega_values);
  for (int i = 0; i < rotors; ++i) {
    if (!std::isfinite(omega_values[i])) {
      fail_step(fmt::format("returned rotor speed {} = {}; not commanded", i + 1, omega_values[i]), t);
    }
  }
  const std::size_t n_outputs = shared_->output_names.size();
  if (figures) {
    if (n_outputs == 0) {
      fail_step("returned (omega, outputs), but the class declares no outputs (outputs = (...names...))", t);
    }
    if (out.outputs.size() < n_outputs) out.outputs.resize(n_outputs);
    read(figures, n_outputs, fmt::format("{} outputs ({})", n_outputs, fmt::join(shared_->output_names, ", ")).c_str(),
         out.outputs.data());
  } else if (n_outputs > 0) {
    fail_step(fmt::format("returned omega alone, expected (omega, outputs) with {} outputs ({})", n_outputs,
                          fmt::join(shared_->output_names, ", ")),
              t);
  }
  ++steps_;
  control::rotor_speeds_output(model_, r, Eigen::Map<const model::RotorVector>(omega_values, rotors), shared_->reported,
                               out);
}

}  // namespace quadcosim::python
