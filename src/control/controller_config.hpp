// What a controller node is configured with: which controller (a configured instance that each node
// clones), the vehicle it believes it flies, and the node's own parameters: the setpoints (mode,
// x_des, ..., yaw_des) and the stale-data safety of Algorithm 1, which are the same for every
// controller. The parameters a node offers are the node's table followed by its controller's; a name
// is looked up in that order (the two tables share no name: ControllerConfig checks).
#pragma once

#include <Eigen/Core>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "control/controller.hpp"
#include "control/parameters.hpp"
#include "model/vehicle_params.hpp"
#include "trajectory/trajectory.hpp"

namespace quadcosim::control {

/// What the controller node commands when its sensor data is stale or missing (Algorithm 1, lines 3-5).
enum class SafetyMode {
  kStop,   ///< all rotors to omega_min (default: a vehicle on the ground stays there)
  kHover,  ///< all rotors at the nominal hover speed (level, uncontrolled)
};

/// The step setpoints: the reference when the scenario gives no trajectory.
struct Setpoint {
  Mode mode = Mode::kAttitude;
  Eigen::Vector3d p_des_W = Eigen::Vector3d::Zero();  ///< [m]; x, y used in position mode
  double roll_des_rad = 0.0;                          ///< used in attitude mode
  double pitch_des_rad = 0.0;                         ///< used in attitude mode
  double yaw_des_rad = 0.0;
};

/// The controller node's own parameters.
struct NodeSettings {
  Setpoint setpoint;
  double stale_limit_s = 0.1;  ///< sensor data older than this triggers the safety command [s]
  SafetyMode safety = SafetyMode::kStop;
};

/// The node's table: mode, x_des, y_des, z_des, roll_des, pitch_des, yaw_des, stale_limit, safety_mode.
const ParameterTable<NodeSettings>& node_parameters();

struct ControllerConfig {
  /// The controller's knowledge of the vehicle (mass, inertia, mixer, motor limits); the safety
  /// command's speeds come from it too.
  model::VehicleParams vehicle;
  NodeSettings node;
  /// The configured controller; every node flies its own clone. Never null once made by
  /// controllers::make_config.
  std::shared_ptr<const Controller> controller;

  /// The reference to track: when set, the node follows it in position mode (its position,
  /// derivatives and yaw at the step's time, shifted by trajectory_offset_W) and the setpoint
  /// parameters (mode, x_des, ..., yaw_des) are not used. Unset: the step setpoints.
  std::shared_ptr<const trajectory::Trajectory> trajectory;
  Eigen::Vector3d trajectory_offset_W = Eigen::Vector3d::Zero();  ///< [m] (a swarm vehicle's grid offset)

  /// The registry name of the controller's type.
  std::string_view type() const { return controller->type(); }
  /// The controller asks to run on a thread of its own (Controller::wants_own_thread).
  bool wants_own_thread() const { return controller->wants_own_thread(); }
};

/// The parameters of a node flying `controller`: the node's, then the controller's.
std::vector<const ParameterSpec*> all_parameters(const Controller& controller);

/// A node or controller parameter's value, or nothing for an unknown name.
std::optional<ParameterValue> get_parameter(const NodeSettings& node, const Controller& controller,
                                            std::string_view name);

/// Checks and applies one value to the node's settings or its controller. Returns "" on success, else
/// why it was refused; then nothing changed.
std::string set_parameter(NodeSettings& node, Controller& controller, std::string_view name,
                          const ParameterValue& value);

/// The declaration of a node or controller parameter, or nullptr.
const ParameterSpec* find_parameter(const ControllerConfig& config, std::string_view name);

/// Every parameter: the node's, then the controller's.
std::vector<const ParameterSpec*> all_parameters(const ControllerConfig& config);

std::optional<ParameterValue> get_parameter(const ControllerConfig& config, std::string_view name);

/// Checks and applies one value to the config (a controller parameter on a copy of its controller,
/// which then replaces it). Returns "" on success, else why it was refused; then `config` is unchanged.
std::string set_parameter(ControllerConfig& config, std::string_view name, const ParameterValue& value);

const char* to_string(SafetyMode mode);

/// The position-mode reference of a trajectory's flat outputs `f`, shifted by `offset_W` (a swarm
/// vehicle's place on its grid), roll and pitch setpoints 0: what a controller flies at each step of a
/// trajectory, in the node (sim::ControllerCore) and in a controller FMU that carries one.
Reference trajectory_reference(const trajectory::FlatOutput& f,
                               const Eigen::Vector3d& offset_W = Eigen::Vector3d::Zero());

}  // namespace quadcosim::control
