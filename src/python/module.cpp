// The Python module quadcosim (its compiled part, quadcosim._quadcosim; the package's __init__.py adds
// load_scenario(), run() and RunResult on top). Scenarios are read and validated by io::load_scenario,
// runs recorded and judged by the code `quadcosim run` uses (hosts/inprocess_run.hpp), so a run from
// Python writes the same bytes as the CLI. The GIL is released around all C++ simulation work.
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

#include "batch.hpp"
#include "control/care.hpp"
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
#include "sensors/suite.hpp"
#include "sim/simulation.hpp"

namespace py = pybind11;
namespace fs = std::filesystem;

namespace quadcosim::python {

namespace {

// ---------------------------------------------------------------------------------------------------
// Scenarios

/// A loaded, validated scenario and the document it came from (kept to reload it with another
/// controller type and to write it as the run's scenario.yaml).
struct PyScenario {
  io::Scenario scenario;
  YAML::Node root;     ///< the parsed document (a mapping)
  std::string source;  ///< the file it was read from, or "<dict>"
  bool from_file = false;
  /// The controller type flown in place of the document's ("python" for a Python object), or "".
  std::string controller_override;
};

/// `source` as text: Python's own shortest round-trip form for floats, YAML's spelling of infinities and
/// NaN. `key` names the place for errors ("simulation.duration_s").
YAML::Node to_yaml(const py::handle& value, const std::string& key) {
  if (value.is_none()) return YAML::Node(YAML::NodeType::Null);
  if (py::isinstance<py::bool_>(value)) return YAML::Node(value.cast<bool>() ? "true" : "false");
  if (py::isinstance<py::str>(value)) {
    // Tagged as a quoted scalar is: a str where a number belongs is refused, as `"1.2"` in a file is.
    YAML::Node text(value.cast<std::string>());
    text.SetTag("!");
    return text;
  }
  if (py::isinstance<py::dict>(value)) {
    YAML::Node map(YAML::NodeType::Map);
    for (const auto& [k, v] : value.cast<py::dict>()) {
      if (!py::isinstance<py::str>(k)) {
        throw io::ConfigError("<dict>: " + (key.empty() ? std::string("top level") : key) + ": key " +
                              py::repr(k).cast<std::string>() + " is not a string");
      }
      const std::string name = k.cast<std::string>();
      map[name] = to_yaml(v, key.empty() ? name : key + "." + name);
    }
    return map;
  }
  if (py::isinstance<py::list>(value) || py::isinstance<py::tuple>(value) ||
      (py::hasattr(value, "tolist") && py::hasattr(value, "ndim") && value.attr("ndim").cast<int>() > 0)) {
    const py::sequence seq = py::isinstance<py::list>(value) || py::isinstance<py::tuple>(value)
                                 ? value.cast<py::sequence>()
                                 : value.attr("tolist")().cast<py::sequence>();
    YAML::Node list(YAML::NodeType::Sequence);
    for (std::size_t i = 0; i < seq.size(); ++i) list.push_back(to_yaml(seq[i], key + "[" + std::to_string(i) + "]"));
    return list;
  }
  const auto object = py::reinterpret_borrow<py::object>(value);
  if (py::hasattr(value, "__index__")) return YAML::Node(py::str(py::int_(object)).cast<std::string>());
  if (py::hasattr(value, "__float__")) {
    const double d = py::float_(object).cast<double>();
    if (std::isnan(d)) return YAML::Node(".nan");
    if (std::isinf(d)) return YAML::Node(d > 0 ? ".inf" : "-.inf");
    return YAML::Node(py::repr(py::float_(d)).cast<std::string>());
  }
  throw io::ConfigError("<dict>: " + key + ": got " + py::repr(value).cast<std::string>() + " of type " +
                        py::str(py::type::of(value).attr("__name__")).cast<std::string>() +
                        ", expected a number, string, bool, None, list or dict");
}

/// Runs `load`, turning the model's and the controller's checks (which name no file) into a
/// ConfigError naming the source, as `quadcosim run` does.
template <class F>
io::Scenario checked(const std::string& source, F load) {
  try {
    return load();
  } catch (const control::CareError& e) {
    throw io::ConfigError(source + ": controller design failed: " + e.what());
  } catch (const io::ConfigError&) {
    throw;
  } catch (const std::invalid_argument& e) {
    throw io::ConfigError(source + ": " + e.what());
  }
}

PyScenario load_file(const std::string& path, const std::string& controller) {
  PyScenario s;
  s.scenario = checked(path, [&] { return io::load_scenario(path, controller, module_resolvers()); });
  s.root = YAML::LoadFile(path);  // read already: cannot fail now
  if (!controller.empty()) io::set_controller_type(s.root, controller);
  s.source = path;
  s.from_file = true;
  s.controller_override = controller;
  return s;
}

PyScenario load_dict(const py::dict& d, const std::string& controller) {
  PyScenario s;
  s.root = to_yaml(d, "");
  if (!controller.empty()) io::set_controller_type(s.root, controller);
  s.source = "<dict>";
  s.controller_override = controller;
  {
    py::gil_scoped_release release;
    s.scenario = checked(s.source, [&] { return io::load_scenario(s.root, s.source, module_resolvers()); });
  }
  return s;
}

/// The same scenario flown by another controller type ("" keeps it).
PyScenario with_controller(const PyScenario& s, const std::string& controller) {
  if (controller.empty()) return s;
  if (s.from_file) return load_file(s.source, controller);
  PyScenario r = s;
  r.root = YAML::Clone(s.root);
  io::set_controller_type(r.root, controller);
  r.controller_override = controller;
  r.scenario = checked(r.source, [&] { return io::load_scenario(r.root, r.source, module_resolvers()); });
  return r;
}

/// The module's resolvers with a Python controller given as an object (quadcosim.run(..., controller=obj))
/// for the scenario naming it: its controller.python, `target` (the object's class, "module:Class"), is
/// made from the object rather than imported.
io::ScenarioResolvers with_given_controller(const std::string& target, const py::object& controller) {
  io::ScenarioResolvers r = module_resolvers();
  r.python = [target, &controller, imported = r.python](
                 const std::string& named, const std::filesystem::path& folder,
                 const model::VehicleParams& vehicle) -> std::shared_ptr<const control::Controller> {
    if (named != target) return imported(named, folder, vehicle);
    try {
      return make_python_controller(controller, vehicle);
    } catch (const ControllerError& e) {
      throw std::invalid_argument(e.what());
    }
  };
  return r;
}

/// "module:Class" of a controller object or class (its class's).
std::string controller_target(const py::handle& controller) {
  const py::handle cls = PyType_Check(controller.ptr()) ? controller : py::type::handle_of(controller);
  return py::str(cls.attr("__module__")).cast<std::string>() + ":" +
         py::str(cls.attr("__qualname__")).cast<std::string>();
}

/// The same scenario flown by a Python controller (an instance or a class): its controller section
/// gets type python and the object's "module:Class", so that the section's and the schedule's
/// parameters are checked against the object's declared ones. step_timeout_s, when given, is set too.
PyScenario with_python_controller(const PyScenario& s, const py::object& controller,
                                  std::optional<double> step_timeout_s) {
  PyScenario r = s;
  r.root = s.from_file ? YAML::LoadFile(s.source) : YAML::Clone(s.root);
  const std::string target = controller_target(controller);
  // As the CLI's --controller python:MODULE:CLASS: another class than the file's own Python class
  // does not inherit that class's parameters (a registered type's flat gains do pass to it).
  io::set_controller_type(r.root, "python:" + target);
  r.controller_override = "python";
  if (r.root["controller"].IsMap()) {
    r.root["controller"]["python"] = target;
    if (step_timeout_s)
      r.root["controller"]["step_timeout_s"] = py::repr(py::float_(*step_timeout_s)).cast<std::string>();
  }
  const io::ScenarioResolvers resolvers = with_given_controller(target, controller);
  r.scenario = checked(r.source, [&] { return io::load_scenario(r.root, r.source, resolvers); });
  return r;
}

/// `controller` of run() and Simulation(): None keeps the scenario's, a str is a controller type, anything
/// else a Python controller (an instance or a class).
PyScenario with_any_controller(const PyScenario& s, const py::object& controller,
                               std::optional<double> step_timeout_s) {
  if (controller.is_none()) {
    if (!step_timeout_s) return s;
    if (s.scenario.controller.type() != "python") {
      throw py::value_error("step_timeout_s: applies to a controller written in Python; this scenario flies '" +
                            std::string(s.scenario.controller.type()) + "'");
    }
    PyScenario r = s;
    r.root = s.from_file ? YAML::LoadFile(s.source) : YAML::Clone(s.root);
    r.root["controller"]["step_timeout_s"] = py::repr(py::float_(*step_timeout_s)).cast<std::string>();
    r.scenario = checked(r.source, [&] { return io::load_scenario(r.root, r.source, module_resolvers()); });
    return r;
  }
  if (py::isinstance<py::str>(controller)) {
    if (step_timeout_s) throw py::value_error("step_timeout_s: applies to a controller written in Python");
    return with_controller(s, controller.cast<std::string>());
  }
  return with_python_controller(s, controller, step_timeout_s);
}

/// A scenario source (a Scenario, a scenario file, a dict) flown by `controller` (None: its own; a str: a
/// controller type; else a Python controller). A document given for a Python controller is checked only
/// once the controller is known, so that its controller section may hold the class's parameters.
PyScenario load_any(const py::object& source, const py::object& controller, std::optional<double> step_timeout_s) {
  if (py::isinstance<PyScenario>(source)) {
    return with_any_controller(source.cast<const PyScenario&>(), controller, step_timeout_s);
  }
  const bool dict = py::isinstance<py::dict>(source);
  const std::string path = dict ? "" : py::module_::import("os").attr("fspath")(source).cast<std::string>();
  if (controller.is_none() || py::isinstance<py::str>(controller)) {
    const std::string type = controller.is_none() ? "" : controller.cast<std::string>();
    const PyScenario s = dict ? load_dict(source.cast<py::dict>(), type) : load_file(path, type);
    return step_timeout_s ? with_any_controller(s, py::none(), step_timeout_s) : s;
  }
  PyScenario raw;
  if (dict) {
    raw.root = to_yaml(source, "");
    raw.source = "<dict>";
  } else {
    raw.root = YAML::Clone(io::YamlSection::load_file(path).node());
    raw.source = path;
    raw.from_file = true;
  }
  if (!raw.root.IsMap()) throw io::ConfigError(raw.source + ": expected a mapping of keys at the top level");
  return with_python_controller(raw, controller, step_timeout_s);
}

// ---------------------------------------------------------------------------------------------------
// Runs

/// trajectory.csv as columns of doubles (every column of the file, by its header name).
std::vector<std::pair<std::string, std::vector<double>>> read_csv_columns(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw std::runtime_error(path.string() + ": cannot open for reading");
  std::string line;
  std::getline(in, line);
  std::vector<std::pair<std::string, std::vector<double>>> columns;
  for (std::size_t b = 0;;) {
    const std::size_t e = line.find(',', b);
    columns.push_back({line.substr(b, e - b), {}});
    if (e == std::string::npos) break;
    b = e + 1;
  }
  for (std::size_t row = 2; std::getline(in, line); ++row) {
    const char* p = line.data();
    const char* end = line.data() + line.size();
    for (std::size_t c = 0; c < columns.size(); ++c) {
      double v = 0.0;
      const auto [next, ec] = std::from_chars(p, end, v);
      if (ec != std::errc() || (next != end && *next != ',')) {
        throw std::runtime_error(path.string() + ": line " + std::to_string(row) + ": column " + columns[c].first +
                                 " is not a number");
      }
      columns[c].second.push_back(v);
      p = next == end ? end : next + 1;
    }
  }
  return columns;
}

std::string read_text(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

/// A temporary folder, removed with everything in it when this goes.
struct TempDir {
  fs::path path;
  TempDir() {
    std::string pattern = (fs::temp_directory_path() / "quadcosim-run-XXXXXX").string();
    if (!mkdtemp(pattern.data())) throw std::runtime_error("cannot create a temporary folder in " + pattern);
    path = pattern;
  }
  ~TempDir() {
    std::error_code ignored;
    fs::remove_all(path, ignored);
  }
};

/// The scenario as flown, as `quadcosim run` writes it: the file, or with the controller applied.
std::string flown_scenario_text(const PyScenario& s) {
  if (s.from_file && s.controller_override != "python") {
    return io::effective_scenario_text(s.source, s.controller_override);
  }
  const std::string comment =
      s.controller_override.empty()
          ? ""
          : "The scenario as flown: " + s.source + " with its controller replaced by the Python class " +
                io::python_target_of(s.root) +
                ".\n(Written by quadcosim from the parsed document; its comments are not kept.)";
  return io::scenario_text(s.root, comment);
}

py::dict columns_dict(std::vector<std::pair<std::string, std::vector<double>>>& columns) {
  py::dict d;
  for (auto& [name, values] : columns) {
    py::array_t<double> a(static_cast<py::ssize_t>(values.size()));
    std::copy(values.begin(), values.end(), a.mutable_data());
    d[py::str(name)] = std::move(a);
  }
  return d;
}

/// Flies `s` as `quadcosim run` does in process; the parts the Python RunResult (or, for a swarm: a
/// scenario with a swarm section or vehicles > 0, the SwarmResult) is made of.
py::dict run(const PyScenario& s, const std::optional<std::string>& out, bool force, const std::string& judge_name,
             int vehicles, int threads) {
  const std::optional<io::Judge> judge = io::parse_judge(judge_name);
  if (!judge) {
    throw py::value_error("judge: got '" + judge_name + "', expected 'spec', 'paper' or 'none'");
  }
  const bool swarm = vehicles > 0 || s.scenario.swarm.has_value();
  const io::SwarmSpec spec = hosts::swarm_spec(s.scenario, vehicles, threads);
  if (swarm) io::check_swarm_fits(spec.layout.vehicles);
  std::optional<TempDir> temp;
  std::optional<io::OutputFolder> folder;
  fs::path dir;
  std::ostringstream notes, info, warn;
  hosts::RunJudgement judged;
  hosts::SwarmJudgement swarm_judged;
  std::vector<std::pair<std::string, std::vector<double>>> columns;
  std::vector<std::string> recorded_dirs;
  std::vector<std::vector<std::pair<std::string, std::vector<double>>>> recorded_columns;
  std::vector<std::string> recorded_metrics, recorded_tables;
  std::string metrics, vehicles_csv;
  bool interrupted = false;
  {
    py::gil_scoped_release release;
    if (out) {
      folder.emplace(io::OutputFolder::claim(*out, "run", {.force = force}, notes));
      dir = *out;
    } else {
      temp.emplace();
      dir = temp->path;
    }
    try {
      const std::string flown = flown_scenario_text(s);
      io::write_file_atomically(dir / "scenario.yaml", flown);
      // Ctrl-C (or any pending Python signal handler's exception) ends the run as it ends the CLI's:
      // what ran stays recorded. Checked every 4096 ticks (~50 µs of simulation) of one vehicle, after
      // each block of ticks of a swarm.
      const auto signalled = [] {
        py::gil_scoped_acquire acquire;
        return PyErr_CheckSignals() != 0;  // the exception stays set for the caller
      };
      const nlohmann::json provenance =
          io::describe_run(s.scenario, {.controller_override = s.controller_override,
                                        .python_target = io::python_target_of(s.root),
                                        .python_module = module_resolvers().python_module});
      if (swarm) {
        recorded_dirs = hosts::make_recorded_dirs(dir, spec, flown);
        interrupted = !hosts::fly_swarm_inprocess(s.scenario, spec, dir, info, [&](double) { return signalled(); });
        if (!interrupted) swarm_judged = hosts::judge_swarm(s.scenario, spec, dir, *judge, provenance);
      } else {
        sim::Tick ticks = 0;
        const auto on_tick = [&](double) { return ++ticks % 4096 == 0 && signalled(); };
        interrupted = !hosts::fly_inprocess(s.scenario, dir, info, warn, on_tick);
        io::add_provenance_to_bag_metadata(dir, provenance);
        if (!interrupted) judged = hosts::judge_run(s.scenario, dir, *judge, provenance);
      }
    } catch (const control::CareError& e) {
      throw io::ConfigError(s.source + ": controller design failed: " + e.what());
    } catch (const std::invalid_argument& e) {
      throw io::ConfigError(s.source + ": " + e.what());
    }
    if (!interrupted && swarm) {
      for (const std::string& d : recorded_dirs) {
        recorded_columns.push_back(read_csv_columns(dir / d / "trajectory.csv"));
        recorded_metrics.push_back(read_text(dir / d / "metrics.json"));
        recorded_tables.push_back(read_text(dir / d / "metrics.txt"));
      }
      metrics = read_text(dir / "summary.json");
      vehicles_csv = read_text(dir / "vehicles.csv");
      for (const std::string& w : swarm_judged.warnings) warn << w << '\n';
    } else if (!interrupted) {
      columns = read_csv_columns(dir / "trajectory.csv");
      metrics = read_text(dir / "metrics.json");
    }
  }
  if (interrupted) throw py::error_already_set();
  py::dict r;
  r["judged"] = io::to_string(*judge);
  r["messages"] = notes.str() + warn.str() + info.str();
  r["out"] = out ? py::object(py::str(*out)) : py::object(py::none());
  if (swarm) {
    py::list recorded;
    for (std::size_t i = 0; i < recorded_dirs.size(); ++i) {
      py::dict v;
      v["namespace"] = "/" + recorded_dirs[i];
      v["trajectory"] = columns_dict(recorded_columns[i]);
      v["metrics_json"] = recorded_metrics[i];
      v["table"] = recorded_tables[i];
      recorded.append(v);
    }
    r["swarm"] = true;
    r["summary_json"] = metrics;
    r["vehicles_csv"] = vehicles_csv;
    r["recorded"] = recorded;
    r["passed"] = *judge == io::Judge::kNone ? py::object(py::none()) : py::object(py::bool_(swarm_judged.passed));
    return r;
  }
  r["swarm"] = false;
  r["trajectory"] = columns_dict(columns);
  r["metrics_json"] = metrics;
  // No verdict under judge="none" (metrics.json's "passed" is null there too).
  r["passed"] = *judge == io::Judge::kNone ? py::object(py::none()) : py::object(py::bool_(judged.passed));
  r["judged_note"] = judged.nothing_note;
  r["table"] = judged.table;
  return r;
}

// ---------------------------------------------------------------------------------------------------
// Stepping

py::array_t<double> array(std::initializer_list<double> v) {
  py::array_t<double> a(static_cast<py::ssize_t>(v.size()));
  std::copy(v.begin(), v.end(), a.mutable_data());
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

  void step(const std::optional<py::array_t<double, py::array::c_style | py::array::forcecast>>& omega_cmd) {
    std::optional<model::Vector4> command;
    if (omega_cmd) {
      if (omega_cmd->ndim() != 1 || omega_cmd->shape(0) != 4) {
        throw py::value_error("Simulation.step: omega_cmd: expected 4 rotor speeds [rad/s], got an array of shape " +
                              py::repr(omega_cmd->attr("shape")).cast<std::string>());
      }
      command = model::Vector4(omega_cmd->at(0), omega_cmd->at(1), omega_cmd->at(2), omega_cmd->at(3));
    }
    auto lock = guard();
    py::gil_scoped_release release;
    stepping_ = std::this_thread::get_id();
    struct Done {
      PySimulation& s;
      ~Done() {
        s.sim_->override_command(std::nullopt);
        s.stepping_ = std::thread::id();
      }
    } done{*this};
    sim_->override_command(command);
    for (int i = 0; i < divider(); ++i) sim_->tick(next_tick_++);
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
    d["omega"] = array({x.omega_rad_s[0], x.omega_rad_s[1], x.omega_rad_s[2], x.omega_rad_s[3]});
    return d;
  }

  py::array_t<double> command() {
    auto lock = guard();
    const model::Vector4& c = sim_->plant().latched_command();
    return array({c[0], c[1], c[2], c[3]});
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

}  // namespace quadcosim::python

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

  py::class_<PyScenario>(m, "Scenario", R"(A validated scenario (see docs/scenarios.md for every key).

Made by quadcosim.load_scenario(path_or_dict); pass it to quadcosim.run() or quadcosim.Simulation().)")
      .def_property_readonly(
          "name", [](const PyScenario& s) { return s.scenario.name; }, "The scenario's name (file stem by default).")
      .def_property_readonly(
          "description", [](const PyScenario& s) { return s.scenario.description; }, "Its description.")
      .def_property_readonly(
          "source", [](const PyScenario& s) { return s.source; }, "The file it was read from, or '<dict>'.")
      .def_property_readonly(
          "controller", [](const PyScenario& s) { return std::string(s.scenario.controller.type()); },
          "The controller type that flies it ('paper', 'se3', ...).")
      .def_property_readonly(
          "duration_s",
          [](const PyScenario& s) {
            return s.scenario.simulation.plant.clock.seconds(s.scenario.simulation.duration_ticks);
          },
          "Simulated time of a run [s] (its last recorded tick).")
      .def_property_readonly(
          "plant_period_s", [](const PyScenario& s) { return s.scenario.simulation.plant.clock.period_s(); },
          "The plant's tick [s] (one trajectory row each).")
      .def_property_readonly(
          "control_period_s",
          [](const PyScenario& s) {
            return s.scenario.simulation.plant.clock.period_s() * s.scenario.simulation.controller_divider;
          },
          "The controller's period [s] (one Simulation.step()).")
      .def_property_readonly(
          "seed", [](const PyScenario& s) { return s.scenario.simulation.plant.realism.seed; },
          "The seed of its sensor noise, wind and other random sources (realism.seed).")
      .def_property_readonly(
          "vehicle", [](const PyScenario& s) { return vehicle_dict(s.scenario.vehicle); },
          "The vehicle as the dict a Python controller's __init__ receives (keys of the vehicle: section, "
          "hover_omega_rad_s, mixer_inverse).")
      .def(
          "yaml",
          [](const PyScenario& s) {
            YAML::Emitter e;
            e << s.root;
            return std::string(e.c_str());
          },
          "The scenario document as YAML text.")
      .def("__repr__",
           [](const PyScenario& s) { return "<quadcosim.Scenario '" + s.scenario.name + "' from " + s.source + ">"; });

  m.def("_load_scenario_file", &load_file, py::arg("path"), py::arg("controller") = "",
        "Loads and validates a scenario file (io::load_scenario).");
  m.def("_load_scenario_dict", &load_dict, py::arg("scenario"), py::arg("controller") = "",
        "Validates a scenario given as a dict with the keys of a scenario file.");
  m.def("_with_controller", &with_controller, py::arg("scenario"), py::arg("controller"),
        "The same scenario flown by another controller type.");
  m.def("_load", &load_any, py::arg("source"), py::arg("controller") = py::none(),
        py::arg("step_timeout_s") = py::none(),
        "A scenario (a Scenario, file or dict) flown by its controller, a controller type (str) or a Python "
        "controller (instance or class).");
  m.def("_run", &run, py::arg("scenario"), py::arg("out"), py::arg("force") = false, py::arg("judge") = "spec",
        py::arg("vehicles") = 0, py::arg("threads") = 0,
        "Runs a scenario in process as `quadcosim run` does; the parts of a RunResult (a SwarmResult for a swarm).");

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
      .def("step", &PySimulation::step, py::arg("omega_cmd") = py::none(),
           R"(Advances one control period (sim.dt seconds, several plant ticks).

With omega_cmd (4 rotor speeds [rad/s], rotors 1..4) the controller is bypassed for this period:
the command goes to the plant on the motor command topic and is checked, limited and latched by the
plant like the controller's (the controller neither steps nor publishes a status).)")
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

  bind_batch(m);
}
