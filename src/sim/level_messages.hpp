// Typed command messages, one per command level (control/command_level.hpp), package quadcosim_msgs:
// what a ROS 2 controller publishes on /<ns>/cmd/<level> (/drone/cmd/ctbr, ...) instead of the untyped
// std_msgs/Float64MultiArray on /<ns>/motor_commands (docs/ros2.md, "Commands at every level").
// Frames as everywhere: world ENU, body FLU; SI units, named in the field names.
//
// header.stamp is what the lockstep label rotors@<ns> of the untyped command is (msg::command_stamp_ns):
// the oldest stamp of the sensor samples the command answers (on ROS time: the control tick's time).
// The plant matches a command to its control tick by it in lockstep; in real time it is not read.
//
// Each message states its fields once (fields(), as sim/messages.hpp), and `values()` / `level_values()`
// say which of the level's four values each field is, in command_level.hpp's order, so the plant's
// one intake (sim::PlantNode) checks and flies a typed command exactly as the same four values named
// by a layout label.
#pragma once

#include <array>
#include <cstddef>
#include <string_view>
#include <vector>

#include "control/command_level.hpp"
#include "sim/messages.hpp"

namespace quadcosim::msg {

/// quadcosim_msgs/msg/RotorSpeeds, level rotor_speeds: omega_1..omega_n [rad/s], rotor i as numbered
/// in the vehicle's mixer (the paper's '+': 1 front, 2 right, 3 back, 4 left seen from above).
struct RotorSpeeds {
  static constexpr std::string_view kRosType = "quadcosim_msgs/msg/RotorSpeeds";
  static constexpr control::CommandLevel kLevel = control::CommandLevel::kRotorSpeeds;
  Header header;
  std::vector<double> omega_rad_s;
  template <class M, class V>
  static void fields(M& m, V& v) {
    v.field("header", m.header);
    v.field("omega_rad_s", m.omega_rad_s);
  }
};

/// quadcosim_msgs/msg/RotorThrusts, level rotor_thrusts: T_1..T_n [N] (omega_i = sqrt(T_i / k_t)).
struct RotorThrusts {
  static constexpr std::string_view kRosType = "quadcosim_msgs/msg/RotorThrusts";
  static constexpr control::CommandLevel kLevel = control::CommandLevel::kRotorThrusts;
  Header header;
  std::vector<double> thrust_n;
  template <class M, class V>
  static void fields(M& m, V& v) {
    v.field("header", m.header);
    v.field("thrust_n", m.thrust_n);
  }
};

/// quadcosim_msgs/msg/ThrustRates, level ctbr: collective thrust along +z_B [N] and body rates p, q, r
/// about x_B, y_B, z_B [rad/s].
struct ThrustRates {
  static constexpr std::string_view kRosType = "quadcosim_msgs/msg/ThrustRates";
  static constexpr control::CommandLevel kLevel = control::CommandLevel::kCtbr;
  Header header;
  double thrust_n = 0.0;
  Vector3 body_rates_rad_s;
  template <class M, class V>
  static void fields(M& m, V& v) {
    v.field("header", m.header);
    v.field("thrust_n", m.thrust_n);
    v.field("body_rates_rad_s", m.body_rates_rad_s);
  }
};

/// quadcosim_msgs/msg/ThrustAttitude, level ctatt: collective thrust [N] and the attitude q_WB (body FLU
/// to world ENU, a unit quaternion), flown as its Z-Y-X roll, pitch, yaw.
struct ThrustAttitude {
  static constexpr std::string_view kRosType = "quadcosim_msgs/msg/ThrustAttitude";
  static constexpr control::CommandLevel kLevel = control::CommandLevel::kCtatt;
  Header header;
  double thrust_n = 0.0;
  Quaternion attitude;
  template <class M, class V>
  static void fields(M& m, V& v) {
    v.field("header", m.header);
    v.field("thrust_n", m.thrust_n);
    v.field("attitude", m.attitude);
  }
};

/// quadcosim_msgs/msg/ThrustTorque, level cttm: collective thrust [N] and the body torques U2..U4 about
/// x_B, y_B, z_B [N m] (the paper's eq. (4)).
struct ThrustTorque {
  static constexpr std::string_view kRosType = "quadcosim_msgs/msg/ThrustTorque";
  static constexpr control::CommandLevel kLevel = control::CommandLevel::kCttm;
  Header header;
  double thrust_n = 0.0;
  Vector3 torque_nm;
  template <class M, class V>
  static void fields(M& m, V& v) {
    v.field("header", m.header);
    v.field("thrust_n", m.thrust_n);
    v.field("torque_nm", m.torque_nm);
  }
};

/// quadcosim_msgs/msg/VelocityYaw, level velocity: velocity in the world frame (ENU) [m/s] and yaw [rad].
struct VelocityYaw {
  static constexpr std::string_view kRosType = "quadcosim_msgs/msg/VelocityYaw";
  static constexpr control::CommandLevel kLevel = control::CommandLevel::kVelocity;
  Header header;
  Vector3 velocity_m_s;
  double yaw_rad = 0.0;
  template <class M, class V>
  static void fields(M& m, V& v) {
    v.field("header", m.header);
    v.field("velocity_m_s", m.velocity_m_s);
    v.field("yaw_rad", m.yaw_rad);
  }
};

/// quadcosim_msgs/msg/AccelerationYaw, level acceleration: acceleration in the world frame (ENU), gravity
/// excluded (0 hovers) [m/s^2], and yaw [rad].
struct AccelerationYaw {
  static constexpr std::string_view kRosType = "quadcosim_msgs/msg/AccelerationYaw";
  static constexpr control::CommandLevel kLevel = control::CommandLevel::kAcceleration;
  Header header;
  Vector3 acceleration_m_s2;
  double yaw_rad = 0.0;
  template <class M, class V>
  static void fields(M& m, V& v) {
    v.field("header", m.header);
    v.field("acceleration_m_s2", m.acceleration_m_s2);
    v.field("yaw_rad", m.yaw_rad);
  }
};

/// A typed command as the level's values in command_level.hpp's order: the rotor levels' own array
/// (`rotors`, any length: the plant checks it), else the four values in `four`. ThrustAttitude's
/// quaternion becomes Z-Y-X roll, pitch, yaw (model::euler_from_quaternion); `attitude_norm` is then the
/// quaternion's norm as sent (the plant refuses one that is not a unit quaternion), 1 otherwise.
struct LevelValues {
  control::CommandLevel level = control::CommandLevel::kRotorSpeeds;
  const std::vector<double>* rotors = nullptr;
  std::array<double, 4> four{};
  double attitude_norm = 1.0;
  const double* data() const { return rotors ? rotors->data() : four.data(); }
  std::size_t count() const { return rotors ? rotors->size() : four.size(); }
};
LevelValues level_values(const RotorSpeeds& m);
LevelValues level_values(const RotorThrusts& m);
LevelValues level_values(const ThrustRates& m);
LevelValues level_values(const ThrustAttitude& m);
LevelValues level_values(const ThrustTorque& m);
LevelValues level_values(const VelocityYaw& m);
LevelValues level_values(const AccelerationYaw& m);

/// Calls f.template operator()<T>() for each typed command message, in command_level.hpp's order.
template <class F>
void for_each_level_message(F&& f) {
  f.template operator()<RotorSpeeds>();
  f.template operator()<RotorThrusts>();
  f.template operator()<ThrustRates>();
  f.template operator()<ThrustAttitude>();
  f.template operator()<ThrustTorque>();
  f.template operator()<VelocityYaw>();
  f.template operator()<AccelerationYaw>();
}

}  // namespace quadcosim::msg
