// The flight controller as a node: keeps the latest Pose, Velocity and Imu (the IMU quaternion is
// turned into Z-Y-X Euler angles, as the paper's imuCallback does), runs FlightController::step on
// its period, and publishes the rotor speeds on /<ns>/motor_commands. Parameters (gains, setpoints)
// change between steps through the declared parameter table.
#pragma once

#include <cstdint>
#include <limits>
#include <string>

#include "control/flight_controller.hpp"
#include "control/parameters.hpp"
#include "sim/messages.hpp"
#include "sim/topics.hpp"
#include "sim/transport.hpp"

namespace quadcosim::sim {

class ControllerNode {
 public:
  /// Throws control::CareError if the initial gains admit no LQR design.
  ControllerNode(Transport& transport, const Topics& topics, const control::ControllerConfig& config);

  /// One control period ending now. `now_ns` is the node's current (simulated) time, `dt_s` its
  /// period; the age of the sensor data is measured against now_ns. Publishes the status, then the
  /// motor command.
  const control::Command& step(std::int64_t now_ns, double dt_s);

  /// Sets one parameter; returns "" on success, else the reason it was refused (nothing changed).
  std::string set_parameter(const std::string& name, const control::ParameterValue& value);

  const control::ControllerConfig& config() const { return config_; }
  const control::Command& last_command() const { return command_; }
  const control::FlightController& controller() const { return controller_; }
  /// The estimate the last step used.
  const control::Estimate& estimate() const { return estimate_; }
  /// The status published by the last step.
  const msg::ControllerStatus& status() const { return status_; }

 private:
  static constexpr std::int64_t kNever = std::numeric_limits<std::int64_t>::min();

  control::ControllerConfig config_;
  control::FlightController controller_;
  control::Estimate estimate_;
  control::Command command_;
  std::int64_t pose_stamp_ns_ = kNever, velocity_stamp_ns_ = kNever, imu_stamp_ns_ = kNever;
  msg::ControllerStatus status_;
  Publisher<msg::ControllerStatus> status_pub_;
  Publisher<msg::Float64MultiArray> command_pub_;
  msg::Float64MultiArray command_msg_;
};

}  // namespace quadcosim::sim
