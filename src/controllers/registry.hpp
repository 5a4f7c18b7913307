// The controllers quadcosim can fly, by name: a scenario's `controller: {type: NAME}` and the CLI's
// `--controller NAME` choose one from this table. Adding a controller: its own folder under
// src/controllers/ (built into quadcosim_controllers automatically) and one line in registry.cpp.
#pragma once

#include <memory>
#include <span>
#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

#include "control/controller.hpp"
#include "control/controller_config.hpp"
#include "model/vehicle_params.hpp"

namespace quadcosim::controllers {

struct ControllerType {
  std::string_view name;
  std::string_view description;  ///< one line for `quadcosim controllers`
  /// A controller with its default parameters for `vehicle`; throws std::exception if it cannot be
  /// designed for it.
  std::unique_ptr<control::Controller> (*make)(const model::VehicleParams& vehicle);
};

/// The type flown where none is named (a scenario's `controller:` without `type:`, the commands'
/// --controller, an exported FMU's configuration): the paper's controller, first in the registry.
inline constexpr std::string_view kDefaultControllerType = "paper";

/// Every registered controller type, the default first.
std::span<const ControllerType> controller_types();

/// The registered names, the default first (for choices and flag checks).
std::vector<std::string> controller_type_list();

/// "paper, se3, ...": the registered names, for messages.
std::string controller_type_names();

/// The type named `name`, or nullptr.
const ControllerType* find_controller_type(std::string_view name);

/// A configuration of a `type` controller with its defaults and the node's defaults, for `vehicle`.
/// Throws std::invalid_argument naming the known types for an unknown one, and what the type's
/// constructor throws when it cannot be designed for the vehicle.
control::ControllerConfig make_config(std::string_view type, const model::VehicleParams& vehicle);

/// The same controller (type and the parameter values set on it) and node settings, for another
/// vehicle: what a scenario's `controller:` section gives once the vehicle is known. A parameter still
/// at its default for the old vehicle takes its default for the new one. Throws as make_config, and
/// std::invalid_argument when a parameter value does not apply to the new vehicle's design.
control::ControllerConfig rebind_vehicle(const control::ControllerConfig& config, const model::VehicleParams& vehicle);

}  // namespace quadcosim::controllers
