#include "python/py_controller.hpp"

#include <fmt/format.h>
#include <fmt/ranges.h>
#include <pybind11/eval.h>
#include <pybind11/numpy.h>
#include <pybind11/stl.h>
#include <Eigen/LU>

#include <algorithm>
#include <array>
#include <atomic>
#include <chrono>
#include <cmath>
#include <condition_variable>
#include <deque>
#include <limits>
#include <mutex>
#include <thread>
#include <tuple>
#include <vector>

#include "control/controller_config.hpp"
#include "io/scenario.hpp"
#include "model/mixer.hpp"
#include "sensors/readings.hpp"
#include "util/did_you_mean.hpp"

namespace py = pybind11;

namespace quadcosim::python {

namespace {

constexpr std::string_view kTimeoutName = "step_timeout_s";

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

// ---------------------------------------------------------------------------------------------------
// Process-wide Python objects, made once under the GIL and kept for the process's life (never released:
// they may be needed until the interpreter finalises).

struct Globals {
  py::object observation_class, reference_class, sensor_reading_class, step_timeout;
  py::object deepcopy, signature;
  // Interned attribute names.
  PyObject *p, *v, *q, *w, *f, *a, *j, *roll, *pitch, *yaw, *yaw_rate, *age, *t, *mode;
  PyObject *attitude, *position;
};

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

// ---------------------------------------------------------------------------------------------------
// The watchdog: one thread per process that raises StepTimeout in a step that overran its limit. A
// step costs it one clock read and two atomic stores; the thread polls the controllers that have a
// limit every tenth of the shortest one (1 ms to 50 ms), and sleeps while there are none.

std::int64_t now_ns() {
  return std::chrono::duration_cast<std::chrono::nanoseconds>(std::chrono::steady_clock::now().time_since_epoch())
      .count();
}

}  // namespace

struct PyController::Watch {
  std::atomic<std::int64_t> deadline_ns{0};  ///< steady clock; 0 while not in a step
  std::atomic<std::int64_t> timeout_ns{0};
  std::atomic<unsigned long> thread_id{0};  ///< the stepping thread (threading.get_ident())
  std::atomic<bool> fired{false};           ///< StepTimeout was raised into the current step
};

namespace {

class Watchdog {
 public:
  static Watchdog& get() {
    static Watchdog* w = new Watchdog;  // never destroyed: its thread may outlive static destruction
    return *w;
  }

  void add(const std::shared_ptr<PyController::Watch>& watch) {
    {
      const std::lock_guard lock(mutex_);
      watches_.push_back(watch);
      if (!started_) {
        std::thread([this] { loop(); }).detach();
        started_ = true;
      }
    }
    wake_.notify_one();
  }

 private:
  void loop() {
    std::unique_lock lock(mutex_);
    for (;;) {
      std::int64_t shortest = std::numeric_limits<std::int64_t>::max();
      std::erase_if(watches_, [](const auto& w) { return w.expired(); });
      for (const auto& weak : watches_) {
        if (auto w = weak.lock(); w && w->timeout_ns.load() > 0) shortest = std::min(shortest, w->timeout_ns.load());
      }
      if (watches_.empty()) {
        wake_.wait(lock);
        continue;
      }
      const std::int64_t poll_ns = shortest == std::numeric_limits<std::int64_t>::max()
                                       ? 50'000'000
                                       : std::clamp<std::int64_t>(shortest / 10, 1'000'000, 50'000'000);
      wake_.wait_for(lock, std::chrono::nanoseconds(poll_ns));
      const std::int64_t now = now_ns();
      std::vector<std::shared_ptr<PyController::Watch>> overdue;
      for (const auto& weak : watches_) {
        auto w = weak.lock();
        if (!w) continue;
        const std::int64_t deadline = w->deadline_ns.load(std::memory_order_acquire);
        if (deadline != 0 && now > deadline) overdue.push_back(std::move(w));
      }
      if (overdue.empty()) continue;
      lock.unlock();
      for (const auto& w : overdue) fire(*w);
      lock.lock();
    }
  }

  static void fire(PyController::Watch& w) {
    if (!python_alive()) return;
    const PyGILState_STATE state = PyGILState_Ensure();
    // Under the GIL the stepping thread is either inside its step (the deadline set, possibly in a
    // C call without the GIL) or outside it (the deadline cleared before it released the GIL): the
    // exception never lands outside the step.
    const std::int64_t deadline = w.deadline_ns.load(std::memory_order_acquire);
    if (deadline != 0 && now_ns() > deadline) {
      w.fired.store(true);
      PyThreadState_SetAsyncExc(w.thread_id.load(), globals().step_timeout.ptr());
    }
    PyGILState_Release(state);
  }

  std::mutex mutex_;
  std::condition_variable wake_;
  std::vector<std::weak_ptr<PyController::Watch>> watches_;
  bool started_ = false;
};

}  // namespace

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

struct PyController::Shared {
  std::string name;                           ///< module.Class
  std::deque<std::string> strings;            ///< owns what the specs' string_views show
  std::vector<control::ParameterSpec> specs;  ///< the declared ones, then step_timeout_s
  std::vector<std::string> declared;          ///< their names (attributes of the object)
  std::vector<std::string> output_names;
  control::ReportedOutputs reported;  ///< where among output_names the class reports its attitude setpoint
  bool has_reset = false, has_set_parameters = false;
};

namespace {
constexpr std::size_t kSensorKinds = std::tuple_size_v<sensors::Kinds>;

/// obs.<sensor> of one extra sensor the vehicle carries: a SensorReading whose attributes are the
/// columns of the registry's kind (sensors/registry.hpp), made once with the Call.
struct SensorView {
  py::object object, dict;       ///< the SensorReading and its __dict__; null when the kind is not carried
  std::vector<py::object> keys;  ///< each column's attribute name (a vector's: its array is in place)
  int at = 0;                    ///< where the sample's packed columns are in SensorViews::buffer
};

/// The step's extra sensors: which kinds the views were made for, each kind's view, the memory of
/// their columns (every carried kind's sample packed, sensors::write_sample).
struct SensorViews {
  unsigned carried = ~0u;
  std::array<SensorView, kSensorKinds> views;
  py::array_t<double> buffer;
  double* data = nullptr;
};

/// Which kinds `readings` carries, one bit per kind (sensors::kind_index).
unsigned carried_kinds(const sensors::Readings& readings) {
  unsigned bits = 0;
  sensors::for_each_kind([&]<class Kind>() {
    if (readings.carries<Kind>()) bits |= 1u << sensors::kind_index<Kind>();
  });
  return bits;
}

/// A stamp [ns] in seconds as a message header's sec + nanosec * 1e-9 (the same double as
/// Simulation.sensors' t).
double stamp_seconds(std::int64_t ns) {
  return static_cast<double>(ns / 1'000'000'000) + static_cast<double>(ns % 1'000'000'000) * 1e-9;
}
}  // namespace

/// The objects of the step call, made at the first step.
struct PyController::Call {
  py::object step;      ///< the bound method
  py::object obs, ref;  ///< Observation and Reference instances
  py::object obs_dict, ref_dict;
  py::array_t<double> buffer;  ///< the arrays' memory: obs p v q w f, ref p v a j
  double* data = nullptr;
  py::object dt;
  double dt_value = std::numeric_limits<double>::quiet_NaN();
  int mode = -1;
  SensorViews sensors;  ///< obs.magnetometer, obs.barometer, obs.gnss
};

namespace {
// Offsets of the arrays in Call::buffer.
enum Offset {
  kObsP = 0,
  kObsV = 3,
  kObsQ = 6,
  kObsW = 10,
  kObsF = 13,
  kRefP = 16,
  kRefV = 19,
  kRefA = 22,
  kRefJ = 25,
  kBufferSize = 28
};

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

/// (Re)makes obs.magnetometer, obs.barometer, obs.gnss for the kinds `readings` carries (None for the
/// others): every number NaN, every flag False and t None until the first sample.
void prepare_sensors(SensorViews& v, const py::object& obs_dict, const sensors::Readings& readings);

/// Writes each carried kind's reading into its view.
void write_sensors(SensorViews& v, const sensors::Readings& readings);
}  // namespace

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

namespace {

void prepare_sensors(SensorViews& v, const py::object& obs_dict, const sensors::Readings& readings) {
  const Globals& g = globals();
  int width = 0;
  sensors::for_each_kind([&]<class Kind>() {
    if (readings.carries<Kind>()) width += sensors::sample_width<Kind>();
  });
  v.buffer = py::array_t<double>(std::max(width, 1));
  v.data = v.buffer.mutable_data();
  std::fill(v.data, v.data + std::max(width, 1), std::numeric_limits<double>::quiet_NaN());
  int at = 0;
  sensors::for_each_kind([&]<class Kind>() {
    SensorView& s = v.views[sensors::kind_index<Kind>()];
    s = SensorView{};
    const py::str name(std::string(Kind::kName));
    if (!readings.carries<Kind>()) {
      obs_dict[name] = py::none();
      return;
    }
    s.object = g.sensor_reading_class();
    s.dict = s.object.attr("__dict__");
    s.at = at;
    for (const auto& col : Kind::kColumns) {
      const py::str key(std::string(col.name));
      if (col.width > 1) {
        s.dict[key] = read_only_view(v.buffer, at, col.width);
      } else {
        s.dict[key] = col.boolean ? py::object(py::bool_(false)) : py::object(py::float_(v.data[at]));
      }
      s.keys.push_back(key);
      at += col.width;
    }
    set_borrowed(s.dict, g.t, Py_None);
    obs_dict[name] = s.object;
  });
  v.carried = carried_kinds(readings);
}

void write_sensors(SensorViews& v, const sensors::Readings& readings) {
  const Globals& g = globals();
  sensors::for_each_kind([&]<class Kind>() {
    const sensors::Reading<Kind>* reading = readings.get<Kind>();
    if (!reading) return;
    const SensorView& s = v.views[sensors::kind_index<Kind>()];
    double* d = v.data + s.at;
    const bool sampled = reading->stamp_ns >= 0;
    if (sampled) {
      sensors::write_sample<Kind>(reading->sample, d);
    } else {
      std::fill(d, d + sensors::sample_width<Kind>(), std::numeric_limits<double>::quiet_NaN());
    }
    for (std::size_t i = 0; i < Kind::kColumns.size(); ++i) {
      const auto& col = Kind::kColumns[i];
      if (col.width == 1 && col.boolean) {
        set_borrowed(s.dict, s.keys[i].ptr(), sampled && d[0] != 0.0 ? Py_True : Py_False);
      } else if (col.width == 1) {
        set_float(s.dict, s.keys[i].ptr(), d[0]);
      }
      d += col.width;
    }
    if (sampled) {
      set_float(s.dict, g.t, stamp_seconds(reading->stamp_ns));
    } else {
      set_borrowed(s.dict, g.t, Py_None);
    }
  });
}

}  // namespace

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
      Watchdog::get().add(watch_);
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
  double omega_values[4];
  read(omega, 4, "4 rotor speeds [rad/s]", omega_values);
  for (int i = 0; i < 4; ++i) {
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
  control::rotor_speeds_output(model_, r,
                               Eigen::Vector4d(omega_values[0], omega_values[1], omega_values[2], omega_values[3]),
                               shared_->reported, out);
}

// ---------------------------------------------------------------------------------------------------
// Making one

py::dict vehicle_dict(const model::VehicleParams& vehicle) {
  py::dict d;
  for (const model::VehicleParameter& p : model::vehicle_parameters()) {
    const py::str key(std::string(p.name));
    switch (p.kind) {
      case model::VehicleParameter::Kind::kNumber: d[key] = p.get(vehicle); break;
      case model::VehicleParameter::Kind::kChoice: d[key] = std::string(p.choice_of(vehicle)); break;
      case model::VehicleParameter::Kind::kSigns: {
        model::VehicleParams copy = vehicle;
        const std::array<int, 4> s = p.signs(copy);
        d[key] = py::make_tuple(s[0], s[1], s[2], s[3]);
        break;
      }
    }
  }
  d["hover_omega_rad_s"] = vehicle.hover_omega_rad_s();
  // The inverse of the mixer (eq. (4)): rotor speeds squared from U, as the C++ controllers allocate.
  const Eigen::Matrix4d inverse = model::mixer_matrix(vehicle).inverse();
  py::list rows;
  for (int r = 0; r < 4; ++r) rows.append(py::make_tuple(inverse(r, 0), inverse(r, 1), inverse(r, 2), inverse(r, 3)));
  d["mixer_inverse"] = py::tuple(rows);
  return d;
}

py::object observation_class() { return globals().observation_class; }
py::object reference_class() { return globals().reference_class; }
py::object sensor_reading_class() { return globals().sensor_reading_class; }

py::object step_timeout_type() {
  py::gil_scoped_acquire gil;
  return globals().step_timeout;
}

namespace {

/// The double a declaration's entry holds, or throws naming it.
double declared_number(const std::string& where, const py::handle& v) {
  if (!is_real_number(v)) {
    throw std::invalid_argument(fmt::format("{}: got {}, expected a number", where, describe_value(v)));
  }
  return py::float_(py::reinterpret_borrow<py::object>(v)).cast<double>();
}

bool valid_parameter_name(const std::string& name) {
  if (name.empty() || !(std::isalpha(static_cast<unsigned char>(name.front())))) return false;
  for (char ch : name) {
    if (!std::isalnum(static_cast<unsigned char>(ch)) && ch != '_' && ch != '.') return false;
  }
  return name.back() != '.' && name.find("..") == std::string::npos;
}

}  // namespace

std::shared_ptr<PyController> make_python_controller(py::object given, const model::VehicleParams& vehicle) {
  py::gil_scoped_acquire gil;
  const Globals& g = globals();
  py::object object = given;
  if (PyType_Check(given.ptr())) {
    const std::string cls = py::str(given.attr("__module__")).cast<std::string>() + "." +
                            py::str(given.attr("__qualname__")).cast<std::string>();
    // With the vehicle when __init__ takes an argument.
    bool takes_vehicle = false;
    try {
      for (const auto& item : g.signature(given).attr("parameters").attr("values")()) {
        const std::string kind = py::str(item.attr("kind").attr("name")).cast<std::string>();
        if (kind == "POSITIONAL_ONLY" || kind == "POSITIONAL_OR_KEYWORD" || kind == "VAR_POSITIONAL") {
          takes_vehicle = true;
        }
      }
    } catch (py::error_already_set&) {
      // No signature (a class implemented in C): called without arguments.
    }
    try {
      object = takes_vehicle ? given(vehicle_dict(vehicle)) : given();
    } catch (py::error_already_set& e) {
      e.restore();
      py::object error = fetch_error();
      throw ControllerError(fmt::format("{}({}) raised {}", cls, takes_vehicle ? "vehicle" : "", describe_error(error)),
                            error);
    }
  }
  const py::handle type = py::type::handle_of(object);
  auto shared = std::make_shared<PyController::Shared>();
  shared->name = py::str(type.attr("__module__")).cast<std::string>() + "." +
                 py::str(type.attr("__qualname__")).cast<std::string>();
  const std::string& name = shared->name;
  if (!py::hasattr(object, "step") || !PyCallable_Check(object.attr("step").ptr())) {
    throw std::invalid_argument(name + ": has no method step(obs, ref, dt) (docs/python.md)");
  }
  shared->has_reset = py::hasattr(object, "reset") && PyCallable_Check(object.attr("reset").ptr());
  shared->has_set_parameters =
      py::hasattr(object, "set_parameters") && PyCallable_Check(object.attr("set_parameters").ptr());

  // parameters = {name: dict(default=, unit=, min=, max=, description=) or a default value}
  std::vector<double> values;
  const py::object declared = py::getattr(object, "parameters", py::none());
  if (!declared.is_none()) {
    if (!py::isinstance<py::dict>(declared)) {
      throw std::invalid_argument(
          fmt::format("{}.parameters: got {}, expected a dict name -> dict(default=, unit=, "
                      "min=, max=, description=)",
                      name, describe_value(declared)));
    }
    for (const auto& [key, spec] : declared.cast<py::dict>()) {
      if (!py::isinstance<py::str>(key)) {
        throw std::invalid_argument(fmt::format("{}.parameters: key {} is not a string", name, describe_value(key)));
      }
      const std::string pname = key.cast<std::string>();
      const std::string where = fmt::format("{}.parameters['{}']", name, pname);
      if (!valid_parameter_name(pname)) {
        throw std::invalid_argument(where +
                                    ": expected a name of letters, digits, '_' and '.', starting with a letter");
      }
      if (control::node_parameters().find(pname) || pname == kTimeoutName) {
        throw std::invalid_argument(where + ": the name is taken by the controller node's own parameter");
      }
      double def = 0.0, lo = -std::numeric_limits<double>::infinity(), hi = std::numeric_limits<double>::infinity();
      std::string unit, description;
      if (py::isinstance<py::dict>(spec)) {
        const py::dict s = spec.cast<py::dict>();
        for (const auto& [k, v] : s) {
          const std::string field = py::str(k).cast<std::string>();
          if (field == "default") {
            def = declared_number(where + "['default']", v);
          } else if (field == "min") {
            lo = declared_number(where + "['min']", v);
          } else if (field == "max") {
            hi = declared_number(where + "['max']", v);
          } else if (field == "unit" || field == "description") {
            if (!py::isinstance<py::str>(v)) {
              throw std::invalid_argument(
                  fmt::format("{}['{}']: got {}, expected a string", where, field, describe_value(v)));
            }
            (field == "unit" ? unit : description) = v.cast<std::string>();
          } else {
            throw std::invalid_argument(
                fmt::format("{}: unknown key '{}'; expected default, unit, min, max, description{}", where, field,
                            util::did_you_mean(field, {"default", "unit", "min", "max", "description"})));
          }
        }
        if (!s.contains("default")) {
          throw std::invalid_argument(where + ": no default; expected dict(default=..., ...)");
        }
      } else {
        def = declared_number(where, spec);
      }
      if (std::isnan(lo) || std::isnan(hi) || lo > hi) {
        throw std::invalid_argument(fmt::format("{}: min {:g} above max {:g}", where, lo, hi));
      }
      const std::string& n = shared->strings.emplace_back(pname);
      const std::string& u = shared->strings.emplace_back(unit);
      const std::string& dsc = shared->strings.emplace_back(
          description.empty() ? "parameter of the Python controller " + name : description);
      control::ParameterSpec ps{n, u, dsc, lo, hi, {}, true};
      // The value: the object's attribute of that name when it has a number there, else the default.
      double value = def;
      const py::object attr = py::getattr(object, pname.c_str(), py::none());
      if (!attr.is_none() && is_real_number(attr)) value = py::float_(attr).cast<double>();
      if (std::string err = control::check_value(ps, value); !err.empty()) {
        throw std::invalid_argument(where + ": " + err +
                                    (value == def ? " (its default)" : " (the object's attribute of that name)"));
      }
      shared->specs.push_back(ps);
      shared->declared.push_back(pname);
      values.push_back(value);
    }
  }
  shared->specs.push_back(control::ParameterSpec{
      kTimeoutName,
      "s",
      "longest a step may run before quadcosim.StepTimeout is raised inside it (0: no limit; a call blocked in C "
      "is only stopped when it returns)",
      0.0,
      1e6,
      {},
      false});

  const py::object outputs = py::getattr(object, "outputs", py::none());
  if (!outputs.is_none()) {
    if (py::isinstance<py::str>(outputs) || !py::isinstance<py::sequence>(outputs)) {
      throw std::invalid_argument(fmt::format("{}.outputs: got {}, expected a tuple of names (\"error.z\", ...)", name,
                                              describe_value(outputs)));
    }
    for (const auto& o : outputs) {
      if (!py::isinstance<py::str>(o) || o.cast<std::string>().empty()) {
        throw std::invalid_argument(
            fmt::format("{}.outputs: got an entry {}, expected names (strings)", name, describe_value(o)));
      }
      shared->output_names.push_back(o.cast<std::string>());
    }
    shared->reported = control::ReportedOutputs::find(shared->output_names);
  }

  double timeout = 0.0;
  if (const py::object t = py::getattr(object, "step_timeout_s", py::none()); !t.is_none()) {
    timeout = declared_number(name + ".step_timeout_s", t);
    if (std::string err = control::check_value(shared->specs.back(), timeout); !err.empty()) {
      throw std::invalid_argument(name + ".step_timeout_s: " + err);
    }
  }
  const std::size_t n_declared = values.size();
  auto c = std::shared_ptr<PyController>(
      new PyController(std::move(shared), std::move(object), std::move(values), timeout, model::Quadrotor(vehicle)));
  std::vector<std::size_t> all(n_declared);
  for (std::size_t i = 0; i < n_declared; ++i) all[i] = i;
  try {
    c->mirror_attributes(all);
  } catch (py::error_already_set& e) {
    throw std::invalid_argument(fmt::format("{}: cannot set its parameters as attributes: {}", c->name(), e.what()));
  }
  return c;
}

std::shared_ptr<PyController> load_python_controller(const std::string& target, const std::filesystem::path& folder,
                                                     const model::VehicleParams& vehicle) {
  const std::size_t colon = target.rfind(':');
  if (colon == std::string::npos || colon == 0 || colon + 1 == target.size()) {
    throw std::invalid_argument("expected module:Class (e.g. my_controllers:AltitudePD), got '" + target + "'");
  }
  const std::string module_name = target.substr(0, colon), class_path = target.substr(colon + 1);
  py::gil_scoped_acquire gil;
  py::object cls;
  try {
    // The scenario's folder and the current directory in front of sys.path while importing.
    py::list path = py::module_::import("sys").attr("path");
    const py::list saved(path);
    const std::string here = std::filesystem::current_path().string();
    const std::string there = folder.empty() ? here : std::filesystem::absolute(folder).lexically_normal().string();
    path.insert(0, there == here ? py::str(here) : py::str(there));
    if (there != here) path.insert(1, py::str(here));
    try {
      cls = py::module_::import("importlib").attr("import_module")(module_name);
    } catch (...) {
      path.attr("__setitem__")(py::slice(0, static_cast<py::ssize_t>(py::len(path)), 1), saved);
      throw;
    }
    path.attr("__setitem__")(py::slice(0, static_cast<py::ssize_t>(py::len(path)), 1), saved);
    std::size_t b = 0;
    for (;;) {
      const std::size_t e = class_path.find('.', b);
      const std::string part = class_path.substr(b, e == std::string::npos ? std::string::npos : e - b);
      if (!py::hasattr(cls, part.c_str())) {
        throw std::invalid_argument(fmt::format("module '{}' ({}) has no '{}'", module_name,
                                                py::str(py::getattr(cls, "__file__", py::str("?"))).cast<std::string>(),
                                                class_path));
      }
      cls = cls.attr(part.c_str());
      if (e == std::string::npos) break;
      b = e + 1;
    }
  } catch (py::error_already_set& e) {
    e.restore();
    throw std::invalid_argument("cannot import " + target + ": " + describe_error(fetch_error()));
  }
  try {
    return make_python_controller(cls, vehicle);
  } catch (const ControllerError& e) {
    throw std::invalid_argument(e.what());
  }
}

std::string loaded_module_file(const std::string& target) {
  const std::size_t colon = target.rfind(':');
  const std::string module_name = target.substr(0, colon == std::string::npos ? target.size() : colon);
  py::gil_scoped_acquire gil;
  const py::dict modules = py::module_::import("sys").attr("modules");
  if (!modules.contains(module_name.c_str())) return "";
  const py::object file = py::getattr(modules[module_name.c_str()], "__file__", py::none());
  return py::isinstance<py::str>(file) ? file.cast<std::string>() : "";
}

}  // namespace quadcosim::python
