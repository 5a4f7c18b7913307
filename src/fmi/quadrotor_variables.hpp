// The names of a quadrotor's FMI variables: what `quadcosim fmu export` gives its plant and
// controller FMUs, and what the master (fmi/fmu_plant.hpp, fmi/fmu_controller.hpp) maps by default
// when a scenario's `plant: {fmu: ...}` or `controller: {fmu: ...}` names no variables. Vectors are
// written as Modelica arrays, 1-based: p_W[1] is x. Frames and symbols are the code's own (docs/model.md):
// W world (z up), B body; q_WB rotates body to world, listed w, x, y, z.
#pragma once

#include <array>
#include <span>
#include <string>
#include <string_view>

namespace quadcosim::fmi::names {

// Plant FMU inputs, controller FMU outputs: one rotor speed command per rotor [rad/s], for the
// vehicle's N rotors (4..8) omega_cmd[1..N]; kOmegaCmd is a quadrotor's four. kRotorNames is
// model::kMaxRotors (this header stays free of Eigen; fmu_variables.cpp checks that they agree).
inline constexpr std::size_t kRotorNames = 8;
inline constexpr std::array<std::string_view, kRotorNames> kOmegaCmdAll = {
    "omega_cmd[1]", "omega_cmd[2]", "omega_cmd[3]", "omega_cmd[4]",
    "omega_cmd[5]", "omega_cmd[6]", "omega_cmd[7]", "omega_cmd[8]"};
inline constexpr std::array<std::string_view, 4> kOmegaCmd = {kOmegaCmdAll[0], kOmegaCmdAll[1], kOmegaCmdAll[2],
                                                              kOmegaCmdAll[3]};

// Controller FMU outputs besides the command: what the latest control step tracked, under the names
// control::ReportedOutputs reads (roll, pitch, yaw of the desired attitude [rad]; the tilt flag [1]),
// then the controller's own figures by their names.
inline constexpr std::array<std::string_view, 3> kReportedAttitude = {"roll_des", "pitch_des", "yaw_des"};
inline constexpr std::string_view kTiltSaturated = "tilt_saturated";

// Plant FMU outputs, controller FMU inputs.
inline constexpr std::array<std::string_view, 3> kPosition = {"p_W[1]", "p_W[2]", "p_W[3]"};  ///< [m]
inline constexpr std::array<std::string_view, 3> kVelocity = {"v_W[1]", "v_W[2]", "v_W[3]"};  ///< [m/s]
/// Attitude quaternion, w x y z [1].
inline constexpr std::array<std::string_view, 4> kAttitude = {"q_WB[1]", "q_WB[2]", "q_WB[3]", "q_WB[4]"};
/// Body angular velocity [rad/s].
inline constexpr std::array<std::string_view, 3> kRates = {"w_B[1]", "w_B[2]", "w_B[3]"};
/// Specific force in the body frame, what an accelerometer reads [m/s2].
inline constexpr std::array<std::string_view, 3> kSpecificForce = {"f_B[1]", "f_B[2]", "f_B[3]"};
// Plant FMU outputs only.
/// Roll, pitch, yaw (Z-Y-X Euler angles) [rad].
inline constexpr std::array<std::string_view, 3> kEuler = {"euler[1]", "euler[2]", "euler[3]"};
/// Rotor speeds reached (after the motors' lag) [rad/s]: omega[1..N]; kRotorSpeed is a quadrotor's four.
inline constexpr std::array<std::string_view, kRotorNames> kRotorSpeedAll = {
    "omega[1]", "omega[2]", "omega[3]", "omega[4]", "omega[5]", "omega[6]", "omega[7]", "omega[8]"};
inline constexpr std::array<std::string_view, 4> kRotorSpeed = {kRotorSpeedAll[0], kRotorSpeedAll[1], kRotorSpeedAll[2],
                                                                kRotorSpeedAll[3]};

/// The names of the first `rotors` (at most model::kMaxRotors) commands or speeds.
inline std::span<const std::string_view> omega_cmd(int rotors) {
  return std::span(kOmegaCmdAll).first(static_cast<std::size_t>(rotors));
}
inline std::span<const std::string_view> rotor_speed(int rotors) {
  return std::span(kRotorSpeedAll).first(static_cast<std::size_t>(rotors));
}

/// The plant FMU's outputs of its extra sensors (sensors/registry.hpp), when the scenario it was
/// exported from configures them: "<sensor>.<column>", a vector's components 1-based
/// ("magnetometer.field[1]", "barometer.pressure", "gnss.v[3]"). `i` counts from 0.
inline std::string sensor_variable(std::string_view sensor, std::string_view column, int width, int i) {
  std::string name(sensor);
  name.append(".").append(column);
  if (width > 1) name.append("[").append(std::to_string(i + 1)).append("]");
  return name;
}

// Plant FMU parameters.
/// The initial state: this prefix + an output's name ("initial.p_W[3]", "initial.q_WB[1]",
/// "initial.omega[2]").
inline constexpr std::string_view kInitialPrefix = "initial.";
/// Vehicle parameters: this prefix + the parameter's name in model::vehicle_parameters()
/// ("vehicle.mass_kg", "vehicle.motor.tau_up_s", "vehicle.aero.linear_drag_N_s_m.x").
inline constexpr std::string_view kVehiclePrefix = "vehicle.";

// Controller FMU inputs besides the sensor values: the reference (flat outputs).
inline constexpr std::array<std::string_view, 3> kRefPosition = {"ref.p_W[1]", "ref.p_W[2]", "ref.p_W[3]"};  ///< [m]
inline constexpr std::array<std::string_view, 3> kRefVelocity = {"ref.v_W[1]", "ref.v_W[2]", "ref.v_W[3]"};  ///< [m/s]
inline constexpr std::array<std::string_view, 3> kRefAcceleration = {"ref.a_W[1]", "ref.a_W[2]",
                                                                     "ref.a_W[3]"};  ///< [m/s2]
inline constexpr std::string_view kRefYaw = "ref.yaw";                               ///< [rad]
/// Controller FMU exported with a trajectory: the Boolean parameter that makes the ref.* inputs the
/// reference instead of the trajectory it carries.
inline constexpr std::string_view kRefExternal = "ref.external";
// Controller FMU parameters: this prefix + the controller's parameter name ("controller.kp_z").
inline constexpr std::string_view kControllerPrefix = "controller.";

}  // namespace quadcosim::fmi::names
