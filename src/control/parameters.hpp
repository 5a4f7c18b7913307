// The controller's runtime parameters, declared once: name, unit, range, meaning, and where the value
// lives. Scenario files, `quadcosim param`, and (over DDS) the ROS 2 parameter services all go through
// this one table, so a parameter is spelt and checked the same everywhere.
#pragma once

#include <optional>
#include <string>
#include <string_view>
#include <variant>
#include <vector>

#include "control/flight_controller.hpp"

namespace quadcosim::control {

/// Everything a controller node can change at runtime: gains, weights, limits and setpoints.
struct ControllerConfig {
  ControllerParams params;
  Setpoint setpoint;
};

using ParameterValue = std::variant<double, std::string>;

struct ParameterSpec {
  std::string_view name;
  std::string_view unit;  ///< SI unit, "" when dimensionless, "choice" for string parameters
  std::string_view description;
  double min = 0.0, max = 0.0;            ///< inclusive range of a numeric parameter
  std::vector<std::string_view> choices;  ///< allowed values of a string parameter
  /// True when changing it needs the LQR re-solved / gains re-applied (not a setpoint).
  bool affects_design = false;
  ParameterValue (*get)(const ControllerConfig&) = nullptr;
  void (*set)(ControllerConfig&, const ParameterValue&) = nullptr;

  bool is_choice() const { return !choices.empty(); }
};

/// All parameters, in a stable documented order.
const std::vector<ParameterSpec>& controller_parameters();

/// The spec named `name`, or nullptr.
const ParameterSpec* find_parameter(std::string_view name);

/// Checks and applies one value. Returns an empty string on success, else why it was refused
/// ("unknown parameter 'z_dse'", "z_des must be in [-1000, 100000] m, got nan", ...); on refusal
/// `config` is unchanged.
std::string set_parameter(ControllerConfig& config, std::string_view name, const ParameterValue& value);

std::optional<ParameterValue> get_parameter(const ControllerConfig& config, std::string_view name);

/// "10" / "attitude": a value as text for tables and logs.
std::string to_string(const ParameterValue& value);

}  // namespace quadcosim::control
