// python/py_controller.hpp: ControllerError, and a PyController's life, copies, parameters and reset (its step:
// py_controller_step.cpp; making one: py_controller_make.cpp).
#include "python/py_controller.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <utility>
#include <vector>

#include "python/py_controller_parts.hpp"
#include "python/py_runtime.hpp"
#include "python/py_watchdog.hpp"

namespace py = pybind11;

namespace quadcosim::python {

// ---------------------------------------------------------------------------------------------------
// Errors

ControllerError::ControllerError(const std::string& message, py::object python_error)
    : control::ControllerFailure(message) {
  if (python_error && !python_error.is_none()) {
    interrupt_ = !PyObject_IsInstance(python_error.ptr(), PyExc_Exception) &&
                 !PyObject_IsInstance(python_error.ptr(), globals().step_timeout.ptr());
    // Released under the GIL, or leaked when Python has gone.
    error_ = std::shared_ptr<PyObject>(python_error.release().ptr(), [](PyObject* o) {
      if (o && python_alive()) {
        py::gil_scoped_acquire gil;
        Py_DECREF(o);
      }
    });
  }
}

ControllerError::ControllerError(const std::string& message) : control::ControllerFailure(message) {}

py::object ControllerError::python_error() const {
  return error_ ? py::reinterpret_borrow<py::object>(error_.get()) : py::object(py::none());
}

// ---------------------------------------------------------------------------------------------------
// The controller

PyController::PyController(std::shared_ptr<const Shared> shared, py::object object, std::vector<double> values,
                           double step_timeout_s, const model::Quadrotor& model)
    : shared_(std::move(shared)),
      object_(new py::object(std::move(object))),
      values_(std::move(values)),
      step_timeout_s_(step_timeout_s),
      model_(model) {}

PyController::~PyController() {
  if (!python_alive()) {
    // The interpreter has gone: its objects with it.
    (void)object_.release();
    (void)call_.release();
    return;
  }
  py::gil_scoped_acquire gil;
  call_.reset();
  object_.reset();
}

const std::string& PyController::name() const { return shared_->name; }

py::object PyController::object() const { return *object_; }

std::unique_ptr<control::Controller> PyController::clone() const {
  py::gil_scoped_acquire gil;
  py::object copy;
  try {
    copy = globals().deepcopy(*object_);
  } catch (py::error_already_set& e) {
    e.restore();
    py::object error = fetch_error();
    throw ControllerError(
        fmt::format("{}: copy.deepcopy failed (every vehicle flies its own copy of the configured object): {}",
                    shared_->name, describe_error(error)),
        error);
  }
  auto c = std::unique_ptr<PyController>(new PyController(shared_, std::move(copy), values_, step_timeout_s_, model_));
  c->steps_ = steps_;
  return c;
}

std::span<const control::ParameterSpec> PyController::parameters() const { return shared_->specs; }

std::optional<control::ParameterValue> PyController::get_parameter(std::string_view name) const {
  for (std::size_t i = 0; i < shared_->declared.size(); ++i) {
    if (shared_->declared[i] == name) return values_[i];
  }
  if (name == kTimeoutName) return step_timeout_s_;
  return std::nullopt;
}

void PyController::mirror_attributes(std::span<const std::size_t> which) const {
  for (std::size_t i : which) {
    object_->attr(shared_->declared[i].c_str()) = py::float_(values_[i]);
  }
}

std::string PyController::set_parameters(std::span<const control::Setting> settings) {
  std::vector<std::pair<std::size_t, double>> next;
  std::optional<double> timeout;
  for (const control::Setting& s : settings) {
    std::size_t i = 0;
    while (i < shared_->specs.size() && shared_->specs[i].name != s.name) ++i;
    if (i == shared_->specs.size()) return control::unknown_parameter(s.name, shared_->specs);
    if (std::string err = control::check_value(shared_->specs[i], s.value); !err.empty()) return err;
    if (i == shared_->declared.size()) {
      timeout = std::get<double>(s.value);
    } else {
      next.emplace_back(i, std::get<double>(s.value));
    }
  }
  if (!next.empty()) {
    py::gil_scoped_acquire gil;
    if (shared_->has_set_parameters) {
      py::dict changes;
      for (const auto& [i, value] : next) changes[py::str(shared_->declared[i])] = value;
      try {
        object_->attr("set_parameters")(changes);
      } catch (py::error_already_set& e) {
        e.restore();
        const py::object error = fetch_error();
        std::string names;
        for (const auto& [i, value] : next) names += (names.empty() ? "" : ", ") + shared_->declared[i];
        const bool refused = PyObject_IsInstance(error.ptr(), PyExc_ValueError) == 1;
        return fmt::format("{}: {} {}.set_parameters: {}", names, refused ? "refused by" : "failed in", shared_->name,
                           refused ? py::str(error).cast<std::string>() : describe_error(error));
      }
    }
    std::vector<std::size_t> which;
    for (const auto& [i, value] : next) {
      values_[i] = value;
      which.push_back(i);
    }
    try {
      mirror_attributes(which);
    } catch (py::error_already_set& e) {
      return fmt::format("{}: cannot set the attribute: {}", shared_->declared[which.front()], e.what());
    }
  }
  if (timeout) {
    step_timeout_s_ = *timeout;
    if (watch_) watch_->timeout_ns.store(static_cast<std::int64_t>(step_timeout_s_ * 1e9));
  }
  return {};
}

std::span<const std::string> PyController::output_names() const { return shared_->output_names; }

void PyController::reset() {
  steps_ = 0;
  if (!shared_->has_reset) return;
  py::gil_scoped_acquire gil;
  try {
    object_->attr("reset")();
  } catch (py::error_already_set& e) {
    e.restore();
    py::object error = fetch_error();
    throw ControllerError(fmt::format("{}.reset raised {}", shared_->name, describe_error(error)), error);
  }
}

void PyController::prepare_call() {
  const Globals& g = globals();
  auto c = std::make_unique<Call>();
  c->step = object_->attr("step");
  c->obs = g.observation_class();
  c->ref = g.reference_class();
  c->obs_dict = c->obs.attr("__dict__");
  c->ref_dict = c->ref.attr("__dict__");
  c->buffer = py::array_t<double>(kBufferSize);
  c->data = c->buffer.mutable_data();
  std::fill(c->data, c->data + kBufferSize, 0.0);
  const auto view = [&](int at, int n) { return read_only_view(c->buffer, at, n); };
  const auto put = [](const py::object& dict, PyObject* key, py::object value) {
    PyDict_SetItem(dict.ptr(), key, value.ptr());
  };
  put(c->obs_dict, g.p, view(kObsP, 3));
  put(c->obs_dict, g.v, view(kObsV, 3));
  put(c->obs_dict, g.q, view(kObsQ, 4));
  put(c->obs_dict, g.w, view(kObsW, 3));
  put(c->obs_dict, g.f, view(kObsF, 3));
  for (PyObject* k : {g.roll, g.pitch, g.yaw, g.age, g.t}) set_float(c->obs_dict, k, 0.0);
  put(c->ref_dict, g.mode, py::reinterpret_borrow<py::object>(g.attitude));
  put(c->ref_dict, g.p, view(kRefP, 3));
  put(c->ref_dict, g.v, view(kRefV, 3));
  put(c->ref_dict, g.a, view(kRefA, 3));
  put(c->ref_dict, g.j, view(kRefJ, 3));
  for (PyObject* k : {g.yaw, g.yaw_rate, g.roll, g.pitch}) set_float(c->ref_dict, k, 0.0);
  call_ = std::move(c);
}

}  // namespace quadcosim::python
