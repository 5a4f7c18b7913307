// A flight controller written in Python as quadcosim's control::Controller (type "python"): what
// `quadcosim.run(scenario, controller=...)`, a scenario's `controller: {python: "module:Class"}` and the
// controller node fly (docs/python.md, "Write a controller in Python"). It holds the Python object and
// calls its step(obs, ref, dt) once per control period; every call into Python takes the GIL and holds
// nothing else across it, so it flies from any thread of a process that hosts an interpreter (the
// extension module, or an executable that embeds one).
//
// The object (duck typed): `step(obs, ref, dt)` returns 4 rotor speeds [rad/s] (any sequence or 1-d
// array of 4 real numbers), or `(omega, outputs)` with one number per name of its `outputs`; optional
// `parameters` (name -> dict(default=, unit=, min=, max=, description=), doubles), `outputs` (names),
// `reset()` and `set_parameters(changes)` (raise ValueError to refuse). A declared parameter's value is
// kept here (the table) and mirrored into the object's attribute of that name before the first step
// and after each accepted change. `obs` and `ref` are two objects reused from step to step whose
// arrays C++ rewrites in place: obs.p, v (3), q (w, x, y, z), w, f (3), obs.roll, pitch, yaw, age, t;
// ref.mode ("attitude"/"position"), p, v, a, j (3), ref.yaw, yaw_rate, roll, pitch. t = n dt at the
// n-th step since the start or the last reset. obs.magnetometer, obs.barometer, obs.gnss: the extra
// sensors' newest samples (control::Observation::sensors), one SensorReading per carried kind with an
// attribute per column of its registry entry (sensors/registry.hpp) and its stamp t [s] (None before
// the first sample); None for a kind the vehicle does not carry.
//
// The status fields are filled as for an FMU controller: U is the wrench of omega on the controller's
// vehicle (eq. (4)), the tracked attitude is the reference's, attitude_error NaN, no saturation flags.
// A step that raises, returns the wrong shape, a non-number or a non-finite speed, or the wrong number
// of outputs throws ControllerError (a std::runtime_error) naming `module.Class.step`, the step number,
// its time and what was wrong: nothing non-finite is ever commanded. With step_timeout_s > 0 (a
// parameter every Python controller has, 0 = no limit) a step that runs longer has StepTimeout raised
// inside it (PyThreadState_SetAsyncExc, from one watchdog thread per process); Python code then stops
// at its next bytecode, a call blocked in C (time.sleep, a socket read) only when it returns.
#pragma once

#include <pybind11/pybind11.h>

#include <filesystem>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "control/controller.hpp"
#include "model/quadrotor.hpp"
#include "model/vehicle_params.hpp"

namespace quadcosim::python {

/// A Python controller failed (raised, returned something that cannot be commanded, timed out, or
/// could not be copied or configured). what() is the whole message; python_error() the Python
/// exception it came from (for `__cause__`), when there was one. A control::ControllerFailure: the CLI
/// exits 5 for it whichever way the controller flies.
class ControllerError : public control::ControllerFailure {
 public:
  ControllerError(const std::string& message, pybind11::object python_error);
  explicit ControllerError(const std::string& message);
  /// The Python exception (None when the failure was found by C++). Take the GIL to use it.
  pybind11::object python_error() const;
  /// True when the Python exception is a KeyboardInterrupt (or another BaseException that is not an
  /// Exception, such as SystemExit): a host passes it on as it is rather than as a controller failure.
  bool interrupt() const { return interrupt_; }

 private:
  /// The exception's reference (a PyObject, not a pybind11::object: the latter's hidden visibility would
  /// not fit an exception class), released under the GIL.
  std::shared_ptr<PyObject> error_;
  bool interrupt_ = false;
};

class PyController final : public control::Controller {
 public:
  /// What every copy of one configured controller shares: its name and declared tables.
  struct Shared;
  /// A controller's slot in the watchdog that enforces step_timeout_s.
  struct Watch;

  ~PyController() override;

  std::string_view type() const override { return "python"; }
  /// A step holds the interpreter's lock and can block: hosts give it a thread (docs/python.md).
  bool wants_own_thread() const override { return true; }
  /// A copy.deepcopy of the object, with the same parameter values and step count.
  std::unique_ptr<control::Controller> clone() const override;
  /// The declared parameters, then step_timeout_s.
  std::span<const control::ParameterSpec> parameters() const override;
  std::optional<control::ParameterValue> get_parameter(std::string_view name) const override;
  /// Range checks, then the object's set_parameters(changes) (a ValueError refuses), then the
  /// attributes. step_timeout_s is not passed to the object.
  std::string set_parameters(std::span<const control::Setting> settings) override;
  std::span<const std::string> output_names() const override;
  /// The object's reset(), when it has one; the step count starts again at 0.
  void reset() override;
  void step(const control::Observation& observation, const control::Reference& reference, double dt_s,
            control::ControllerOutput& out) override;

  /// "module.Class".
  const std::string& name() const;
  /// The configured object (this copy's). Take the GIL to use it.
  pybind11::object object() const;
  /// The per-step time limit [s]; 0: none.
  double step_timeout_s() const { return step_timeout_s_; }

 private:
  friend std::shared_ptr<PyController> make_python_controller(pybind11::object, const model::VehicleParams&);
  struct Call;  ///< the step's Python objects (bound method, obs, ref, their arrays)
  PyController(std::shared_ptr<const Shared> shared, pybind11::object object, std::vector<double> values,
               double step_timeout_s, const model::Quadrotor& model);
  [[noreturn]] void fail_step(const std::string& what, double t, pybind11::object cause = {});
  void mirror_attributes(std::span<const std::size_t> which) const;
  void prepare_call();

  std::shared_ptr<const Shared> shared_;
  std::unique_ptr<pybind11::object> object_;  ///< released under the GIL
  std::vector<double> values_;                ///< each declared parameter's current value
  double step_timeout_s_ = 0.0;
  long long steps_ = 0;
  model::Quadrotor model_;
  std::unique_ptr<Call> call_;  ///< made at the first step
  std::shared_ptr<Watch> watch_;
};

/// A Python controller from `instance_or_class`: a class is instantiated (with the vehicle as a dict,
/// keyed as a scenario's `vehicle:` section, when its __init__ takes an argument); an instance is the
/// configured object itself (each node flies a copy.deepcopy of it). Reads its `parameters` and
/// `outputs` declarations. Throws std::invalid_argument for an object quadcosim cannot fly (no step,
/// a bad declaration), naming what is wrong, and ControllerError when its class's __init__ raises.
/// Takes the GIL.
std::shared_ptr<PyController> make_python_controller(pybind11::object instance_or_class,
                                                     const model::VehicleParams& vehicle);

/// `target` "module:Class" (or "module:Outer.Inner") imported with `folder` and the current directory
/// in front of sys.path, then make_python_controller. Throws std::invalid_argument naming what was
/// wrong (the import's exception as "ModuleNotFoundError: No module named 'x'"). Takes the GIL.
std::shared_ptr<PyController> load_python_controller(const std::string& target, const std::filesystem::path& folder,
                                                     const model::VehicleParams& vehicle);

/// The source file of the module of `target` ("module:Class") as this interpreter imported it
/// (sys.modules[module].__file__), or "" when it is not imported here or has no file. Takes the GIL.
std::string loaded_module_file(const std::string& target);

/// The vehicle as the dict a Python controller's __init__ receives: every entry of
/// model::vehicle_parameters() by its YAML path ("mass_kg", "motor.omega_max_rad_s", ...; a 3-vector
/// as three entries .x, .y, .z; choices as strings, spin as a tuple), hover_omega_rad_s and
/// mixer_inverse (4 rows of 4: rotor speeds squared = mixer_inverse U, as the C++ controllers allocate).
pybind11::dict vehicle_dict(const model::VehicleParams& vehicle);

/// The classes of a step's `obs` and `ref` (quadcosim.Observation, quadcosim.Reference) and of
/// obs.magnetometer, obs.barometer, obs.gnss (quadcosim.SensorReading). Take the GIL.
pybind11::object observation_class();
pybind11::object reference_class();
pybind11::object sensor_reading_class();

/// The Python exception type raised inside a step that overran step_timeout_s: quadcosim.StepTimeout, a
/// BaseException (so that `except Exception:` in the controller does not swallow it). Takes the GIL.
pybind11::object step_timeout_type();

}  // namespace quadcosim::python
