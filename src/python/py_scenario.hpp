// Scenarios in the Python module (quadcosim.Scenario, quadcosim.load_scenario's compiled part): read and
// validated by io::load_scenario with the module's resolvers, flown by the scenario's controller, another
// controller type or a Python controller given as an object or a class.
#pragma once

#include <pybind11/pybind11.h>
#include <yaml-cpp/yaml.h>

#include <optional>
#include <string>

#include "io/scenario.hpp"

namespace quadcosim::python {

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

/// A scenario source (a Scenario, a scenario file, a dict) flown by `controller` (None: its own; a str: a
/// controller type; else a Python controller). A document given for a Python controller is checked only
/// once the controller is known, so that its controller section may hold the class's parameters.
PyScenario load_any(const pybind11::object& source, const pybind11::object& controller,
                    std::optional<double> step_timeout_s);

/// Adds Scenario, _load_scenario_file, _load_scenario_dict, _with_controller and _load to the module.
void bind_scenario(pybind11::module_& m);

}  // namespace quadcosim::python
