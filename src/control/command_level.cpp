#include "control/command_level.hpp"

#include <cmath>
#include <sstream>
#include <vector>

#include "util/did_you_mean.hpp"

namespace quadcosim::control {

namespace {
constexpr std::array<std::string_view, kCommandLevelCount> kNames = {
    "rotor_speeds", "rotor_thrusts", "ctbr", "ctatt", "cttm", "velocity", "acceleration"};
constexpr std::array<std::array<std::string_view, 4>, kCommandLevelCount> kFields = {{
    {"omega_1 [rad/s]", "omega_2 [rad/s]", "omega_3 [rad/s]", "omega_4 [rad/s]"},
    {"T_1 [N]", "T_2 [N]", "T_3 [N]", "T_4 [N]"},
    {"thrust [N]", "p [rad/s]", "q [rad/s]", "r [rad/s]"},
    {"thrust [N]", "roll [rad]", "pitch [rad]", "yaw [rad]"},
    {"thrust [N]", "torque_x [N m]", "torque_y [N m]", "torque_z [N m]"},
    {"v_x [m/s]", "v_y [m/s]", "v_z [m/s]", "yaw [rad]"},
    {"a_x [m/s^2]", "a_y [m/s^2]", "a_z [m/s^2]", "yaw [rad]"},
}};
}  // namespace

std::string_view to_string(CommandLevel level) { return kNames[static_cast<std::size_t>(level)]; }

const std::array<std::string_view, kCommandLevelCount>& command_level_names() { return kNames; }

std::optional<CommandLevel> command_level_from_string(std::string_view name) {
  for (std::size_t i = 0; i < kNames.size(); ++i) {
    if (kNames[i] == name) return static_cast<CommandLevel>(i);
  }
  return std::nullopt;
}

std::string unknown_command_level(std::string_view name) {
  std::vector<std::string> names(kNames.begin(), kNames.end());
  std::string known;
  for (std::string_view n : kNames) known += (known.empty() ? "" : ", ") + std::string(n);
  return "unknown command level '" + std::string(name) + "'; the levels are " + known + util::did_you_mean(name, names);
}

const std::array<std::string_view, 4>& setpoint_fields(CommandLevel level) {
  return kFields[static_cast<std::size_t>(level)];
}

std::string check_setpoint(CommandLevel level, const double* values, std::size_t count) {
  std::ostringstream err;
  err << to_string(level) << ": ";
  if (count != 4) {
    err << "expected 4 values, got " << count;
    return err.str();
  }
  for (std::size_t i = 0; i < 4; ++i) {
    const double v = values[i];
    if (!std::isfinite(v)) {
      err << "value " << i + 1 << " (" << setpoint_fields(level)[i] << ") is " << v << ", expected a finite number";
      return err.str();
    }
  }
  return {};
}

}  // namespace quadcosim::control
