// A flight controller (control::Controller, any registered type) as a node: keeps the latest Pose,
// Velocity and Imu (the IMU quaternion is also turned into Z-Y-X Euler angles, as the paper's
// imuCallback does), evaluates the reference (the step setpoints, or the scenario's trajectory) and
// steps the controller on its period, and publishes the rotor speeds on /<ns>/motor_commands and its
// status on /<ns>/controller_status. The stale-data safety of Algorithm 1 is the node's: when the
// observation is older than stale_limit or not finite, the node commands the safety speeds and the
// controller is not stepped. Parameters (the node's setpoints and safety, the controller's own table)
// change between steps. Sensor messages that fail the checks of
// sim/validation.hpp (NaN/Inf, non-unit quaternion, malformed or backward stamp) are dropped, counted
// in the status and logged (1st of each reason, then every 100th): the observation keeps its last valid
// values and ages, so the stale-data safety (Algorithm 1) takes over when nothing valid arrives.
#pragma once

#include <Eigen/Geometry>
#include <array>
#include <cstdint>
#include <functional>
#include <limits>
#include <string>

#include <memory>
#include "control/controller.hpp"
#include "control/controller_config.hpp"
#include "sim/messages.hpp"
#include "sim/topics.hpp"
#include "sim/transport.hpp"
#include "sim/validation.hpp"

namespace quadcosim::sim {

class ControllerNode {
 public:
  /// Flies a clone of config.controller (which must be set).
  ControllerNode(Transport& transport, const Topics& topics, const control::ControllerConfig& config);

  /// One control period ending now. `now_ns` is the node's current (simulated) time, `dt_s` its
  /// period; the age of the sensor data is measured against now_ns. Publishes the status, then the
  /// motor command.
  const control::ControllerOutput& step(std::int64_t now_ns, double dt_s);

  /// Real time: measure the age of sensor data by when it arrived on `clock` [ns] instead of by its
  /// stamp, so a plant that stops publishing is noticed even though its simulated time stops too.
  /// step() then takes now_ns on that clock.
  void use_receipt_clock(std::function<std::int64_t()> clock) { receipt_clock_ = std::move(clock); }

  /// The newest stamp [ns] among Pose, Velocity, Imu (simulated time), or -1 before any arrived.
  std::int64_t newest_stamp_ns() const;

  /// Publishes the last status and command again (a lockstep peer that asked twice for one tick).
  void republish();

  /// Time [ns] of the last step, or INT64_MIN before the first.
  std::int64_t last_step_ns() const { return last_step_ns_; }

  /// Sets one parameter (the node's or the controller's); returns "" on success, else the reason it
  /// was refused (nothing changed).
  std::string set_parameter(const std::string& name, const control::ParameterValue& value);
  /// A parameter's value, or nothing for an unknown name.
  std::optional<control::ParameterValue> get_parameter(std::string_view name) const;
  /// Every parameter the node offers: its own, then its controller's.
  std::vector<const control::ParameterSpec*> parameters() const;

  const control::NodeSettings& settings() const { return settings_; }
  const control::ControllerOutput& last_output() const { return output_; }
  const control::Controller& controller() const { return *controller_; }
  /// The reference the last step followed.
  const control::Reference& reference() const { return reference_; }
  /// The observation the last step used.
  const control::Observation& observation() const { return observation_; }
  /// The stamp [ns] shared by the newest Pose, Velocity and Imu, when all three have arrived with the
  /// same stamp (a complete sample of one plant tick); -1 otherwise.
  std::int64_t synchronized_stamp_ns() const;

  /// Called after each Pose, Velocity or Imu message taken in, where the transport delivers it: a
  /// lockstep host steps from here (LockstepStepper) instead of polling after every wait.
  void on_sample(std::function<void()> f) { on_sample_ = std::move(f); }

  /// Where refused sensor messages are reported (rate-limited per reason). Default: stderr.
  void set_log(std::function<void(const std::string&)> log) { log_ = std::move(log); }

  /// The status published by the last step.
  const msg::ControllerStatus& status() const { return status_; }

 private:
  static constexpr std::int64_t kNever = std::numeric_limits<std::int64_t>::min();

  /// True when a message on `topic` is to be used: its check passed, or else (accept_refused) it is
  /// the sample after a sender's clock restart; a refusal is counted and logged. `backwards`: the
  /// topic's run of well-formed samples refused as older than the newest (kStampRestartCount of them
  /// in a row: the sender's clock restarted, and the sample is accepted).
  bool accept(const SensorCheck& check, const std::string& topic, int& backwards) {
    if (check.ok()) {
      backwards = 0;
      return true;
    }
    return accept_refused(check, topic, backwards);
  }
  bool accept_refused(const SensorCheck& check, const std::string& topic, int& backwards);

  void safety_output();
  /// reference_ at simulated time now_ns: the step setpoints (or the trajectory).
  void update_reference(std::int64_t now_ns);

  model::VehicleParams vehicle_;
  std::shared_ptr<const trajectory::Trajectory> trajectory_;
  Eigen::Vector3d trajectory_offset_W_;
  control::NodeSettings settings_;
  std::unique_ptr<control::Controller> controller_;
  control::Reference reference_;
  control::Observation observation_;
  control::ControllerOutput output_;
  /// Header stamps of the newest samples, and the times their age is measured from (the stamps, or
  /// the receipt times under use_receipt_clock).
  std::int64_t pose_stamp_ns_ = kNever, velocity_stamp_ns_ = kNever, imu_stamp_ns_ = kNever;
  std::int64_t pose_ref_ns_ = kNever, velocity_ref_ns_ = kNever, imu_ref_ns_ = kNever;
  std::function<std::int64_t()> receipt_clock_;
  std::int64_t reference(std::int64_t stamp_ns) const { return receipt_clock_ ? receipt_clock_() : stamp_ns; }
  std::int64_t last_step_ns_ = kNever;
  bool imu_pending_ = false;  ///< observation_.q_WB not yet turned into its Euler angles
  msg::ControllerStatus status_;
  std::function<void(const std::string&)> log_;
  std::function<void()> on_sample_;
  std::array<LogThrottle, kSensorFaultCount> fault_log_;  ///< per SensorFault: counts and log pacing
  int pose_backwards_ = 0, velocity_backwards_ = 0, imu_backwards_ = 0;
  Publisher<msg::ControllerStatus> status_pub_;
  Publisher<msg::Float64MultiArray> command_pub_;
  msg::Float64MultiArray command_msg_;
};

}  // namespace quadcosim::sim
