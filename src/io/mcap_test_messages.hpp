// Test-only: deterministic sample messages of the six recorded types for tick `i` of a 100 Hz run,
// with values that exercise CDR alignment (strings of varying length, empty and non-empty sequences,
// booleans before and after doubles) and decimal fractions that only survive an exact round trip.
#pragma once

#include <cstdint>
#include <string>

#include "sim/messages.hpp"

namespace quadcosim::io::testing {

inline std::int64_t tick_ns(int i) { return std::int64_t{i} * 10'000'000; }

inline msg::Header sample_header(int i, std::string frame) {
  return {msg::Time::from_ns(tick_ns(i)), std::move(frame)};
}

inline msg::Clock sample_clock(int i) { return {msg::Time::from_ns(tick_ns(i))}; }

inline msg::PoseStamped sample_pose(int i) {
  msg::PoseStamped m;
  m.header = sample_header(i, "world");
  m.position = {0.1 * i, -0.5 * i, 1.0 + i / 3.0};
  m.orientation = {0.001 * i, -0.002 * i, 0.01, 1.0 - 1e-6 * i};
  return m;
}

inline msg::TwistStamped sample_twist(int i) {
  msg::TwistStamped m;
  m.header = sample_header(i, "world");
  m.linear = {0.3 * i, -0.7, 1e-9 * i};
  m.angular = {-0.01 * i, 0.02 * i, i / 7.0};
  return m;
}

inline msg::Imu sample_imu(int i) {
  msg::Imu m;
  m.header = sample_header(i, "base_link");
  m.orientation = {0.1, 0.2, 0.3, 0.9 - 0.001 * i};
  m.orientation_covariance[0] = (i % 2) ? -1.0 : 0.0;  // ROS: -1 = unknown
  for (int k = 0; k < 3; ++k) {
    m.angular_velocity_covariance[4 * k] = 1e-4 * (i + k);
    m.linear_acceleration_covariance[4 * k] = 0.05 * (k + 1);
  }
  m.angular_velocity = {0.01 * i, -0.02 * i, 0.5};
  m.linear_acceleration = {-0.1 * i, 0.0, 9.81 + 0.001 * i};
  return m;
}

inline msg::Float64MultiArray sample_command(int i) {
  msg::Float64MultiArray m;
  m.data = {4830.6 + i, 4830.6 - i, 4830.6 + 0.5 * i, 4830.6 - 0.25 * i};
  m.dim = {{msg::command_label(tick_ns(i)), 4, 1}};
  m.data_offset = 0;
  return m;
}

inline msg::ControllerStatus sample_status(int i) {
  msg::ControllerStatus m;
  m.header = sample_header(i, "");
  m.controller = i % 3 == 2 ? "se3" : "paper";
  m.mode = i < 100 ? "attitude" : "position";
  m.setpoint = {0.0, 0.0, 1.0 + 0.01 * i, 0.1, -0.1, i / 9.0};
  m.u = {19.2276 + 0.1 * i, 0.001 * i, -0.002 * i, 0.0};
  m.position_error = {0.25 - 0.001 * i, -0.003 * i, 0.5 - 0.005 * i};
  m.yaw_error = 1e-5 * i;
  m.attitude_error = 1e-4 * i;
  // The paper controller's figures; a different number of them for the other type (none at all for
  // some), so the sequences' lengths vary.
  if (m.controller == "paper") {
    m.output_names = {"error.z", "error.roll", "error.pitch", "error.yaw"};
    m.outputs = {0.5 - 0.005 * i, 0.01, -0.01, 1e-5 * i};
  } else if (i % 2 == 0) {
    m.output_names = {"thrust_axis.z"};
    m.outputs = {0.99 - 1e-4 * i};
  }
  m.rotor_saturated = {i % 2 == 0, i % 3 == 0, false, true};
  m.tilt_saturated = i % 5 == 0;
  m.safety = i % 7 == 0;
  m.rejected_non_finite = static_cast<std::uint64_t>(i) / 3;
  m.rejected_bad_quaternion = static_cast<std::uint64_t>(i) / 5;
  m.rejected_bad_stamp = i % 2;
  m.rejected_stamp_backwards = 0x0102030405060708ull + static_cast<std::uint64_t>(i);  // all 8 bytes in use
  m.rejected_stamp_ahead = static_cast<std::uint64_t>(i) * 11;
  return m;
}

inline msg::PlantStatus sample_plant_status(int i) {
  msg::PlantStatus m;
  m.header = sample_header(i, "world");
  m.commands_accepted = static_cast<std::uint64_t>(i) / 2;
  m.commands_clamped = static_cast<std::uint64_t>(i) / 7;
  m.commands_rejected_length = static_cast<std::uint64_t>(i) % 3;
  m.commands_rejected_non_finite = 0xfedcba9876543210ull - static_cast<std::uint64_t>(i);
  m.last_problem = i % 4 == 0 ? "" : "rotor 2 speed " + std::to_string(-i) + " rad/s clamped to 0";
  m.watchdog_active = i % 3 == 1;
  m.watchdog_trips = static_cast<std::uint64_t>(i) / 5;
  m.watchdog_ticks = 0x0123456789abcdefull + static_cast<std::uint64_t>(i);
  m.commands_stale = static_cast<std::uint64_t>(i) * 3;
  m.commands_foreign = 0x8000000000000000ull + static_cast<std::uint64_t>(i);
  m.commands_rejected_second_topic = static_cast<std::uint64_t>(i) % 5;
  m.commands_rejected_bad_quaternion = 0xffffffffffffffffull - static_cast<std::uint64_t>(i);
  return m;
}

}  // namespace quadcosim::io::testing
