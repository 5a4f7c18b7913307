// Topic names of one vehicle. The namespace is a setting so several vehicles share a domain.
#pragma once

#include <array>
#include <string>

#include "control/command_level.hpp"

namespace quadcosim::sim {

struct Topics {
  std::string motor_commands;     ///< controller -> plant, std_msgs/Float64MultiArray
  std::string pose;               ///< plant ->, geometry_msgs/PoseStamped
  std::string velocity;           ///< plant ->, geometry_msgs/TwistStamped
  std::string imu;                ///< plant ->, sensor_msgs/Imu
  std::string clock;              ///< plant ->, rosgraph_msgs/Clock (global, not namespaced)
  std::string controller_status;  ///< controller ->, quadcosim_msgs/ControllerStatus
  std::string plant_status;       ///< plant ->, quadcosim_msgs/PlantStatus
  /// plant ->, tf2_msgs/TFMessage: world -> <ns>/base_link, every tick (global: all vehicles share it)
  std::string tf;
  std::string tf_static;          ///< plant ->, tf2_msgs/TFMessage: base_link -> rotors, once (global)
  std::string robot_description;  ///< plant ->, std_msgs/String: the vehicle's URDF, once
  std::string scene;              ///< recorded only, foxglove_msgs/SceneUpdate: the vehicle drawn
  /// The namespace the vehicle's topics are under ("/drone"; "" for "/"): the extra sensors' topics
  /// are formed under it (sim/sensor_wire.hpp).
  std::string ns;
  /// controller -> plant, the typed commands: /<ns>/cmd/<level> ("/drone/cmd/ctbr"), one per command
  /// level in control/command_level.hpp's order, quadcosim_msgs/RotorSpeeds ... AccelerationYaw
  /// (sim/level_messages.hpp)
  std::array<std::string, control::kCommandLevelCount> level_commands;

  /// Topics under `ns` ("/drone" gives "/drone/Pose", ...). `ns` must start with '/'.
  static Topics for_namespace(const std::string& ns = "/drone");
};

/// Empty when `ns` is a valid ROS namespace ("/drone", "/uav1"), else why not.
std::string validate_namespace(const std::string& ns);

}  // namespace quadcosim::sim
