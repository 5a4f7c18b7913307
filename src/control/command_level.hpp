// The command levels a vehicle can be flown at: what a controller (or a Python action, a Batch step)
// hands the vehicle, from rotor speeds (what the plant's motors take) up to a velocity setpoint. Every
// level above rotor speeds is turned into rotor speeds on the plant side, every plant tick, by the
// inner loops (control/inner_loops.hpp), which end in the allocation of a wrench (control/allocation.hpp).
// Frames as everywhere in quadcosim: world W is ENU (z up), body B is FLU (x forward, z up).
//
//   level           values                                   units
//   rotor_speeds    omega_1..omega_N, one per rotor           [rad/s]   (the default; today's command)
//   rotor_thrusts   T_1..T_4 (four-rotor vehicles only)       [N]       omega_i = sqrt(T_i / k_t)
//   ctbr            U1, p, q, r: collective thrust along +z_B, body rates about x_B, y_B, z_B
//                                                             [N], [rad/s]
//   ctatt           U1, roll, pitch, yaw: thrust and the attitude R_WB as Z-Y-X angles
//                                                             [N], [rad]
//   cttm            U1, U2, U3, U4: collective thrust and body torques about x_B, y_B, z_B (eq. (4))
//                                                             [N], [N m]
//   velocity        v_x, v_y, v_z (world), yaw                [m/s], [rad]
//   acceleration    a_x, a_y, a_z (world, gravity excluded: 0 hovers), yaw
//                                                             [m/s^2], [rad]
#pragma once

#include <Eigen/Core>
#include <array>
#include <optional>
#include <string>
#include <string_view>

namespace quadcosim::control {

enum class CommandLevel : unsigned char {
  kRotorSpeeds,   ///< omega_i [rad/s]
  kRotorThrusts,  ///< T_i [N]
  kCtbr,          ///< collective thrust [N] + body rates [rad/s]
  kCtatt,         ///< collective thrust [N] + roll, pitch, yaw [rad]
  kCttm,          ///< collective thrust [N] + body torques [N m]
  kVelocity,      ///< world velocity [m/s] + yaw [rad]
  kAcceleration,  ///< world acceleration [m/s^2] (gravity excluded) + yaw [rad]
};
constexpr int kCommandLevelCount = 7;

/// The level's name as scenarios, Python and messages spell it ("rotor_speeds", "ctbr", ...).
std::string_view to_string(CommandLevel level);
/// The level named `name`; nothing for an unknown name.
std::optional<CommandLevel> command_level_from_string(std::string_view name);
/// "unknown command level 'ctrb'; the levels are rotor_speeds, rotor_thrusts, ctbr, ... (did you mean 'ctbr'?)".
std::string unknown_command_level(std::string_view name);
/// All the names, in the enum's order.
const std::array<std::string_view, kCommandLevelCount>& command_level_names();

/// The names and units of a level's values, in order ("thrust [N]", "p [rad/s]", ...).
const std::array<std::string_view, 4>& setpoint_fields(CommandLevel level);

/// A command at one level (a "setpoint" of that level): four values (rotor_thrusts: one per rotor of a
/// four-rotor vehicle). Rotor speeds, N of them, are latched as they are and never held as one.
struct LevelCommand {
  CommandLevel level = CommandLevel::kRotorSpeeds;
  Eigen::Vector4d value = Eigen::Vector4d::Zero();
};

/// "" when `values` (as sent: `count` of them) can be a setpoint of `level`: exactly 4 finite values.
/// Else why not, naming the level, the value and its field ("ctbr: value 3 (q [rad/s]) is nan,
/// expected a finite number"). Values beyond what the vehicle can do (a negative rotor thrust, a torque
/// the rotors cannot make) are not refused: the inner loops clamp them and flag it.
std::string check_setpoint(CommandLevel level, const double* values, std::size_t count);

}  // namespace quadcosim::control
