// python/py_simulation.hpp: quadcosim.Simulation.
#include "python/py_simulation.hpp"

#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>
#include <yaml-cpp/yaml.h>

#include <stdlib.h>

#include <atomic>
#include <charconv>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <limits>
#include <mutex>
#include <optional>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "control/care.hpp"
#include "control/command_level.hpp"
#include "hosts/inprocess_run.hpp"
#include "hosts/swarm_inprocess.hpp"
#include "io/output_folder.hpp"
#include "io/provenance.hpp"
#include "io/scenario.hpp"
#include "io/scenario_limits.hpp"
#include "io/trajectory_csv.hpp"
#include "io/yaml_reader.hpp"
#include "python/module_resolvers.hpp"
#include "python/py_controller.hpp"
#include "python/py_scenario.hpp"
#include "sensors/suite.hpp"
#include "sim/simulation.hpp"

namespace py = pybind11;

namespace quadcosim::python {

namespace {

py::array_t<double> array(std::initializer_list<double> v) {
  py::array_t<double> a(static_cast<py::ssize_t>(v.size()));
  std::copy(v.begin(), v.end(), a.mutable_data());
  return a;
}

py::array_t<double> array(const model::RotorVector& v) {
  py::array_t<double> a(static_cast<py::ssize_t>(v.size()));
  std::copy(v.data(), v.data() + v.size(), a.mutable_data());
  return a;
}

double stamp_s(const msg::Header& h) { return h.stamp.sec + h.stamp.nanosec * 1e-9; }

/// One vehicle of a scenario, advanced one control period at a time.
class PySimulation {
 public:
  PySimulation(const py::object& scenario, std::optional<std::uint64_t> seed, const py::object& controller,
               std::optional<double> step_timeout_s)
      : scenario_(load_any(scenario, controller, step_timeout_s).scenario) {
    seed_ = seed ? *seed : scenario_.simulation.plant.realism.seed;
    build();
  }

  void reset(std::optional<std::uint64_t> seed) {
    auto lock = guard();
    if (seed) seed_ = *seed;
    build();
  }

  using Values = py::array_t<double, py::array::c_style | py::array::forcecast>;

  void step(const std::optional<Values>& omega_cmd, const std::optional<Values>& command,
            const std::optional<std::string>& level) {
    if (omega_cmd && command) {
      throw py::value_error("Simulation.step: give omega_cmd (rotor speeds) or command (with level), not both");
    }
    if (level && !command) throw py::value_error("Simulation.step: level='" + *level + "' needs command=");
    std::optional<model::RotorVector> speeds;
    std::optional<control::LevelCommand> given;
    if (omega_cmd) speeds = rotor_speeds(*omega_cmd, "omega_cmd");
    if (command) {
      const std::string name = level.value_or("rotor_speeds");
      const std::optional<control::CommandLevel> l = control::command_level_from_string(name);
      if (!l) throw py::value_error("Simulation.step: " + control::unknown_command_level(name));
      if (*l == control::CommandLevel::kRotorSpeeds) {
        speeds = rotor_speeds(*command, "command");
      } else {
        given = level_command(*command, *l);
      }
    }
    auto lock = guard();
    py::gil_scoped_release release;
    stepping_ = std::this_thread::get_id();
    struct Done {
      PySimulation& s;
      ~Done() {
        s.sim_->override_level_command(std::nullopt);
        s.stepping_ = std::thread::id();
      }
    } done{*this};
    if (speeds) {
      sim_->override_command(speeds);
    } else {
      sim_->override_level_command(given);
    }
    for (int i = 0; i < divider(); ++i) sim_->tick(next_tick_++);
  }

  /// `values` as rotor speeds: one-dimensional, one per rotor of the vehicle; else ValueError naming
  /// `arg`. Speeds out of range are not refused here: the plant checks and limits them as any command.
  model::RotorVector rotor_speeds(const Values& values, const char* arg) const {
    const int rotors = scenario_.vehicle.rotor_count;
    if (values.ndim() != 1 || values.shape(0) != rotors) {
      throw py::value_error(std::string("Simulation.step: ") + arg + ": expected " + std::to_string(rotors) +
                            " rotor speeds [rad/s], got an array of shape " +
                            py::repr(values.attr("shape")).cast<std::string>());
    }
    return Eigen::Map<const model::RotorVector>(values.data(), rotors);
  }
  /// `values` as a command at `level` (above rotor speeds): one-dimensional, the level's 4 values, finite
  /// (control::check_setpoint); rotor_thrusts only for a four-rotor vehicle. Else ValueError.
  control::LevelCommand level_command(const Values& values, control::CommandLevel level) const {
    if (values.ndim() != 1 || values.shape(0) != 4) {
      throw py::value_error("Simulation.step: command: expected 4 values (" + std::string(control::to_string(level)) +
                            ": " + fields_text(level) + "), got an array of shape " +
                            py::repr(values.attr("shape")).cast<std::string>());
    }
    if (level == control::CommandLevel::kRotorThrusts && scenario_.vehicle.rotor_count != 4) {
      throw py::value_error("Simulation.step: rotor_thrusts is a four-rotor level; the vehicle has " +
                            std::to_string(scenario_.vehicle.rotor_count) + " rotors");
    }
    if (std::string why = control::check_setpoint(level, values.data(), 4); !why.empty()) {
      throw py::value_error("Simulation.step: command: " + why);
    }
    return {level, Eigen::Vector4d(values.at(0), values.at(1), values.at(2), values.at(3))};
  }
  static std::string fields_text(control::CommandLevel level) {
    std::string text;
    for (std::string_view f : control::setpoint_fields(level)) text += (text.empty() ? "" : ", ") + std::string(f);
    return text;
  }

  void set_setpoint(const py::kwargs& values) {
    auto lock = guard();
    static const std::map<std::string, std::string> names = {
        {"x", "x_des"},         {"y", "y_des"},     {"z", "z_des"},  {"roll", "roll_des"},
        {"pitch", "pitch_des"}, {"yaw", "yaw_des"}, {"mode", "mode"}};
    for (const auto& [k, v] : values) {
      const std::string key = k.cast<std::string>();
      const auto name = names.find(key);
      if (name == names.end()) {
        throw py::type_error("Simulation.set_setpoint: unknown setpoint '" + key +
                             "'; expected x, y, z [m], roll, pitch, yaw [rad] or mode ('attitude' or 'position')");
      }
      control::ParameterValue value;
      if (key == "mode") {
        value = v.cast<std::string>();
      } else {
        value = py::float_(py::reinterpret_borrow<py::object>(v)).cast<double>();
      }
      if (std::string why = sim_->controller().set_parameter(name->second, value); !why.empty()) {
        throw py::value_error("Simulation.set_setpoint: " + key + " = " + py::repr(v).cast<std::string>() + ": " + why);
      }
    }
  }

  double t() {
    auto lock = guard();
    return scenario_.simulation.plant.clock.seconds(next_tick_);
  }
  sim::Tick tick() {
    auto lock = guard();
    return next_tick_;
  }
  double dt() const { return scenario_.simulation.plant.clock.period_s() * divider(); }
  std::uint64_t seed() {
    auto lock = guard();
    return seed_;
  }

  py::dict state() {
    auto lock = guard();
    const model::State& x = sim_->plant().state();
    py::dict d;
    d["p"] = array({x.p_W.x(), x.p_W.y(), x.p_W.z()});
    d["v"] = array({x.v_W.x(), x.v_W.y(), x.v_W.z()});
    d["q"] = array({x.q_WB.w(), x.q_WB.x(), x.q_WB.y(), x.q_WB.z()});
    d["w"] = array({x.w_B.x(), x.w_B.y(), x.w_B.z()});
    d["omega"] = array(x.omega_rad_s);
    return d;
  }

  py::array_t<double> command() {
    auto lock = guard();
    const model::RotorVector& c = sim_->plant().latched_command();
    return array(c);
  }

  py::dict sensors() {
    auto lock = guard();
    py::dict d;
    if (pose_) {
      d["pose"] =
          py::dict(py::arg("t") = stamp_s(pose_->header),
                   py::arg("p") = array({pose_->position.x, pose_->position.y, pose_->position.z}),
                   py::arg("q") =
                       array({pose_->orientation.w, pose_->orientation.x, pose_->orientation.y, pose_->orientation.z}));
    }
    if (velocity_) {
      d["velocity"] =
          py::dict(py::arg("t") = stamp_s(velocity_->header),
                   py::arg("v") = array({velocity_->linear.x, velocity_->linear.y, velocity_->linear.z}),
                   py::arg("w") = array({velocity_->angular.x, velocity_->angular.y, velocity_->angular.z}));
    }
    if (imu_) {
      const auto& m = *imu_;
      d["imu"] =
          py::dict(py::arg("t") = stamp_s(m.header),
                   py::arg("q") = array({m.orientation.w, m.orientation.x, m.orientation.y, m.orientation.z}),
                   py::arg("w") = array({m.angular_velocity.x, m.angular_velocity.y, m.angular_velocity.z}),
                   py::arg("a") = array({m.linear_acceleration.x, m.linear_acceleration.y, m.linear_acceleration.z}));
    }
    // The extra sensors the scenario configures (docs/sensors.md): the newest sample of each, as the
    // plant published it (sensors/suite.hpp), column by column in SI units.
    if (const sensors::Suite* suite = sim_->plant().extra_sensors()) {
      const sim::TickClock& clock = scenario_.simulation.plant.clock;
      sensors::for_each_kind([&]<class Kind>() {
        const sensors::Slot<Kind>* slot = suite->slot<Kind>();
        if (!slot || slot->tick < 0) return;
        py::dict one;
        one["t"] = stamp_s(msg::Header{msg::Time::from_ns(clock.ns(slot->tick)), ""});
        for (const auto& c : Kind::kColumns) {
          std::array<double, sensors::sample_width<Kind>()> v{};
          c.write(slot->sample, v.data());
          if (c.width > 1) {
            py::array_t<double> a(c.width);
            std::copy(v.begin(), v.begin() + c.width, a.mutable_data());
            one[py::str(std::string(c.name))] = a;
          } else if (c.boolean) {
            one[py::str(std::string(c.name))] = py::bool_(v[0] != 0.0);
          } else {
            one[py::str(std::string(c.name))] = v[0];
          }
        }
        d[py::str(std::string(Kind::kName))] = one;
      });
    }
    return d;
  }

  py::dict setpoint() {
    auto lock = guard();
    const control::Setpoint& s = sim_->controller().settings().setpoint;
    py::dict d;
    d["mode"] = s.mode == control::Mode::kPosition ? "position" : "attitude";
    d["x"] = s.p_des_W.x();
    d["y"] = s.p_des_W.y();
    d["z"] = s.p_des_W.z();
    d["roll"] = s.roll_des_rad;
    d["pitch"] = s.pitch_des_rad;
    d["yaw"] = s.yaw_des_rad;
    return d;
  }

  std::string repr() {
    auto lock = guard();
    return "<quadcosim.Simulation '" + scenario_.name +
           "' t=" + py::repr(py::float_(scenario_.simulation.plant.clock.seconds(next_tick_))).cast<std::string>() +
           " s, seed " + std::to_string(seed_) + ">";
  }

 private:
  int divider() const { return scenario_.simulation.controller_divider; }

  /// The lock of this simulation, taken with the GIL released (a step holds the lock and takes the GIL
  /// to call a Python controller). Refused from inside a step of this simulation on its own thread (a
  /// Python controller calling back into the simulation that steps it).
  std::unique_lock<std::mutex> guard() {
    if (stepping_.load() == std::this_thread::get_id()) {
      throw std::runtime_error(
          "Simulation: called from inside its own step (a Python controller cannot use the simulation that flies it)");
    }
    py::gil_scoped_release release;
    return std::unique_lock<std::mutex>(mutex_);
  }

  void build() {
    io::Scenario sc = scenario_;
    sc.simulation.plant.realism.seed = seed_;
    sc.simulation.faults.seed = seed_;
    // Stepped for as long as the caller likes: the loop integrates after every tick (it skips the
    // integration after the last tick only).
    sc.simulation.duration_ticks = std::numeric_limits<sim::Tick>::max() / 4;
    pose_.reset();
    velocity_.reset();
    imu_.reset();
    sim_.reset();
    try {
      sim_ = std::make_unique<sim::Simulation>(sc.simulation, sc.vehicle, io::initial_state(sc), sc.controller,
                                               sc.schedule);
    } catch (const std::invalid_argument& e) {
      throw io::ConfigError(sc.path + ": " + e.what());
    }
    const sim::Topics topics = sim::Topics::for_namespace(sc.simulation.ns);
    auto& t = sim_->transport();
    t.subscribe<msg::PoseStamped>(topics.pose, [this](const msg::PoseStamped& m) { pose_ = m; });
    t.subscribe<msg::TwistStamped>(topics.velocity, [this](const msg::TwistStamped& m) { velocity_ = m; });
    t.subscribe<msg::Imu>(topics.imu, [this](const msg::Imu& m) { imu_ = m; });
    next_tick_ = 0;
  }

  io::Scenario scenario_;
  std::uint64_t seed_ = 0;
  std::unique_ptr<sim::Simulation> sim_;
  sim::Tick next_tick_ = 0;  ///< the next plant tick to run
  std::optional<msg::PoseStamped> pose_;
  std::optional<msg::TwistStamped> velocity_;
  std::optional<msg::Imu> imu_;
  std::mutex mutex_;                         ///< one thread steps or reads at a time (stepping runs without the GIL)
  std::atomic<std::thread::id> stepping_{};  ///< the thread inside step(), if any
};

}  // namespace

void bind_simulation(py::module_& m) {
  py::class_<PySimulation>(m, "Simulation", R"(One vehicle of a scenario, stepped one control period at a time.

The plant and the scenario's controller run in lockstep exactly as in quadcosim.run() (the same
ticks, schedule and seeded noise), so after n steps the state equals row n * (plant ticks per control
period) of the run's trajectory, bit for bit.

    sim = quadcosim.Simulation(quadcosim.load_scenario("scenarios/paper/altitude_step.yaml"))
    for _ in range(100):
        sim.step()                   # the controller flies one period (sim.dt seconds)
    sim.t, sim.state["p"]            # 2.0, array([x, y, z])
    sim.set_setpoint(z=5.0)          # a new altitude for the controller
    sim.step(omega_cmd=np.full(4, 400.0))  # rotor speeds [rad/s] for one period, controller bypassed
    sim.reset(seed=7)                # back to t = 0 (with another seed for the noise)

Scheduled parameter changes of the scenario apply at their times; a scenario with a trajectory
follows it and ignores set_setpoint's position and yaw.)")
      .def(py::init<const py::object&, std::optional<std::uint64_t>, const py::object&, std::optional<double>>(),
           py::arg("scenario"), py::arg("seed") = py::none(), py::kw_only(), py::arg("controller") = py::none(),
           py::arg("step_timeout_s") = py::none(),
           R"(Builds the vehicle and controller at t = 0.

scenario: a Scenario, a scenario file or a dict (as quadcosim.load_scenario takes).
controller: None keeps the scenario's; a str is a controller type (as --controller); anything else is a
controller written in Python, an instance or a class (see docs/python.md, "Write a controller in
Python"): each Simulation flies its own copy.deepcopy of the configured object.
seed replaces the scenario's seed of sensor noise, wind and injected message faults (None keeps
realism.seed). step_timeout_s: the per-step time limit of a Python controller (0: none).)")
      .def("step", &PySimulation::step, py::arg("omega_cmd") = py::none(), py::kw_only(),
           py::arg("command") = py::none(), py::arg("level") = py::none(),
           R"(Advances one control period (sim.dt seconds, several plant ticks).

With omega_cmd (one speed per rotor [rad/s], rotors 1..N) the controller is bypassed for this period:
the command goes to the plant on the motor command topic and is checked, limited and latched by the
plant like the controller's (the controller neither steps nor publishes a status).
With command= and level= (a command level: "rotor_thrusts", "ctbr", "ctatt", "cttm", "velocity",
"acceleration"; its 4 values in quadcosim.action_levels' order and units) the controller is bypassed
the same way and the plant's inner loops fly that level at the plant rate, as for a controller that
outputs it. A level command is held until the next command.)")
      .def("set_setpoint", &PySimulation::set_setpoint,
           R"(Sets the controller node's setpoints by keyword, from the next step on:
x, y, z [m] (x and y in position mode), roll, pitch [rad] (attitude mode), yaw [rad], and
mode ('attitude' or 'position'). A value out of range raises ValueError naming it.)")
      .def("reset", &PySimulation::reset, py::arg("seed") = py::none(),
           "Back to t = 0, the scenario's initial state and setpoints. seed: a new seed (None keeps the current "
           "one), so reset() repeats the same numbers.")
      .def_property_readonly("t", &PySimulation::t, "Simulated time [s] of the state.")
      .def_property_readonly("tick", &PySimulation::tick, "The plant tick of the state (t / plant period).")
      .def_property_readonly("dt", &PySimulation::dt, "The control period [s]: what one step() advances.")
      .def_property_readonly("seed", &PySimulation::seed, "The seed in use.")
      .def_property_readonly("state", &PySimulation::state,
                             R"(The plant's true state at t, a dict of numpy float64 arrays:
p (3) position in the world frame [m], v (3) velocity in the world frame [m/s],
q (4) attitude body -> world as w, x, y, z, w (3) body angular velocity [rad/s],
omega (4) rotor speeds [rad/s].)")
      .def_property_readonly("command", &PySimulation::command,
                             "The rotor command [rad/s] the plant latched in the last tick (numpy, 4).")
      .def_property_readonly("sensors", &PySimulation::sensors,
                             R"(The latest sensor messages the plant published (the controller's inputs, after
any noise, latency and injected faults), a dict of dicts with their stamp t [s]:
pose: p (3) [m], q (4, w x y z); velocity: v (3) world [m/s], w (3) body [rad/s];
imu: q (4), w (3) [rad/s], a (3) specific force in body [m/s^2]. Empty before the first step.
With the scenario's extra sensors (docs/sensors.md), the newest sample of each as the plant drew it
(before any injected message fault), with its stamp t: magnetometer: field (3) body [T];
barometer: pressure [Pa], altitude [m] (its ISA pressure altitude); gnss: fix (bool),
latitude_deg, longitude_deg, altitude_m (NaN without a fix), v (3) world ENU [m/s].)")
      .def_property_readonly("setpoint", &PySimulation::setpoint,
                             "The controller node's setpoints: mode, x, y, z [m], roll, pitch, yaw [rad].")
      .def("__repr__", &PySimulation::repr);
}

}  // namespace quadcosim::python
