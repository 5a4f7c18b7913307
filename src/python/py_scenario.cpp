// python/py_scenario.hpp: loading scenarios for the Python module.
#include "python/py_scenario.hpp"

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

namespace quadcosim::python {

namespace {

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

}  // namespace

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

void bind_scenario(py::module_& m) {
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
}

}  // namespace quadcosim::python
