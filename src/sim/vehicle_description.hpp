// What a vehicle looks like to ROS 2 and Foxglove tools: its tf2 frame names, a URDF of it (the
// /<ns>/robot_description robot_state_publisher would publish), the transforms from base_link to its
// rotors (/tf_static) and a foxglove_msgs SceneUpdate drawing the same shapes. All built from the
// vehicle parameters: rotor positions from the mixer geometry (model::rotor_position_B), sizes in
// proportion to the arm length (docs/recording.md, "The vehicle in 3D").
#pragma once

#include <array>
#include <string>

#include <Eigen/Core>

#include "model/vehicle_params.hpp"
#include "sim/messages.hpp"
#include "sim/scene_messages.hpp"

namespace quadcosim::sim {

/// The tf2 frame prefix of a vehicle's namespace, as multi-robot ROS setups name frames: the
/// namespace without its leading '/', then '/' ("/drone" -> "drone/", "/team/uav0001" ->
/// "team/uav0001/"; the root namespace "/" -> ""). tf2 frame ids never start with '/'.
std::string tf_prefix(const std::string& ns);

/// Sizes [m] of the drawn vehicle and where its rotors are (body frame, FLU).
struct VehicleShape {
  double arm_length = 0;    ///< centre of mass to rotor axis: the vehicle's arm_length_m
  double arm_width = 0;     ///< arm cross-section, square: 0.05 of the arm length
  double body_side = 0;     ///< body cube side (x and y): 0.4 of the arm length
  double body_height = 0;   ///< 0.15 of the arm length
  double rotor_radius = 0;  ///< aero.ground_effect_rotor_radius_m when set, else 0.4 of the arm length
  double rotor_height = 0;  ///< rotor disc thickness: 0.02 of the arm length
  double rotor_lift = 0;    ///< rotor disc centre above its rotor link (the arm's top): arm_width/2 + rotor_height/2
  int rotor_count = 4;      ///< the first rotor_count entries below are used
  std::array<Eigen::Vector3d, model::kMaxRotors> rotor_B;  ///< rotor i+1 position, model::rotor_position_B
  std::array<double, model::kMaxRotors> arm_B{};           ///< arm i+1's drawn length (centre to the rotor axis)
};
VehicleShape vehicle_shape(const model::VehicleParams& p);

/// A URDF of the vehicle: link `<prefix>base_link` (the body and one arm per rotor as visuals, the mass
/// and inertia of the vehicle) and one link `<prefix>rotor_<i>` per rotor (i = 1..N, the layout's numbering),
/// each a rotor disc, attached to base_link by fixed joints at the rotor positions. Link names carry
/// the frame prefix, so RViz's RobotModel finds them in /tf without a TF prefix setting.
std::string vehicle_urdf(const model::VehicleParams& p, const std::string& prefix, const std::string& robot_name);

/// The fixed joints of vehicle_urdf as transforms base_link -> rotor_<i> (for /tf_static), stamped `stamp`.
msg::TFMessage rotor_transforms(const model::VehicleParams& p, const std::string& prefix, const msg::Time& stamp);

/// One SceneEntity (id "<prefix>vehicle", frame_id `<prefix>base_link`, frame_locked, lifetime zero:
/// kept until replaced) drawing vehicle_urdf's shapes: the body and the arms as cubes, the
/// rotor discs as cylinders, and an arrow along +x_B marking the nose.
msg::SceneUpdate vehicle_scene(const model::VehicleParams& p, const std::string& prefix, const msg::Time& stamp);

/// Everything above for the vehicle in namespace `ns` ("/drone"), stamped `stamp`: what the plant
/// publishes once (robot_description, /tf_static) and what a recording adds (the scene). The URDF's
/// robot is named after the namespace ("drone"; "quadrotor" in the root namespace).
struct VehicleDescription {
  msg::String urdf;
  msg::TFMessage rotors;
  msg::SceneUpdate scene;
};
VehicleDescription describe_vehicle(const model::VehicleParams& p, const std::string& ns, const msg::Time& stamp);

}  // namespace quadcosim::sim
