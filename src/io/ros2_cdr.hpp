// ROS 2 serialized messages without a ROS 2 installation: the CDR bytes rosbag2 stores for a message
// (what rmw_serialize gives) and the `ros2msg` schema text MCAP's ros2 profile asks for.
//
// Wire format (OMG CDR as XCDR1, as ROS 2 puts it on DDS and in bags): a 4-byte encapsulation header
// 00 01 00 00 (CDR_LE, no options), then the fields in IDL order (src/dds/idl/*.idl), little-endian,
// each primitive aligned to its size counted from the end of the header; string: uint32 length
// including the terminating NUL, the bytes, NUL; sequence: uint32 count, then the elements; fixed
// array: the elements only; bool: one byte 0 or 1. No padding after the last field.
#pragma once

#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

#include "sim/level_messages.hpp"
#include "sim/messages.hpp"
#include "sim/scene_messages.hpp"

namespace quadcosim::io {

/// The CDR (little-endian, with encapsulation header) bytes of a message, byte for byte what
/// Cyclone DDS / rmw_cyclonedds serialise for the same ROS 2 type.
std::vector<std::uint8_t> to_cdr(const msg::PoseStamped& m);
std::vector<std::uint8_t> to_cdr(const msg::TwistStamped& m);
std::vector<std::uint8_t> to_cdr(const msg::Imu& m);
std::vector<std::uint8_t> to_cdr(const msg::MagneticField& m);
std::vector<std::uint8_t> to_cdr(const msg::FluidPressure& m);
std::vector<std::uint8_t> to_cdr(const msg::NavSatFix& m);
std::vector<std::uint8_t> to_cdr(const msg::Float64MultiArray& m);
std::vector<std::uint8_t> to_cdr(const msg::Clock& m);
std::vector<std::uint8_t> to_cdr(const msg::ControllerStatus& m);
std::vector<std::uint8_t> to_cdr(const msg::PlantStatus& m);
std::vector<std::uint8_t> to_cdr(const msg::TFMessage& m);
std::vector<std::uint8_t> to_cdr(const msg::String& m);
std::vector<std::uint8_t> to_cdr(const msg::SceneUpdate& m);
std::vector<std::uint8_t> to_cdr(const msg::RotorSpeeds& m);
std::vector<std::uint8_t> to_cdr(const msg::RotorThrusts& m);
std::vector<std::uint8_t> to_cdr(const msg::ThrustRates& m);
std::vector<std::uint8_t> to_cdr(const msg::ThrustAttitude& m);
std::vector<std::uint8_t> to_cdr(const msg::ThrustTorque& m);
std::vector<std::uint8_t> to_cdr(const msg::VelocityYaw& m);
std::vector<std::uint8_t> to_cdr(const msg::AccelerationYaw& m);

/// The full `ros2msg` schema text of a ROS 2 message type named "pkg/msg/Type" (e.g.
/// "geometry_msgs/msg/PoseStamped", as each message struct's kRosType), as msg::ros2msg_definition
/// (sim/message_schema.hpp) derives it from the types' fields(). Throws std::invalid_argument naming
/// `ros_type` for a type that is not one of them.
const std::string& ros2msg_definition(std::string_view ros_type);

/// The `offered_qos_profiles` channel metadata the MCAP ros2 profile requires, in rosbag2's YAML
/// (bag format version 9, Jazzy): one publisher offering KEEP_LAST `depth`, RELIABLE or BEST_EFFORT,
/// VOLATILE or TRANSIENT_LOCAL, infinite deadline/lifespan/lease, AUTOMATIC liveliness — what
/// quadcosim's nodes offer (dds/participant.hpp ros_qos). An empty string ("unknown, use defaults") is
/// also valid for rosbag2.
std::string ros2_offered_qos_profiles(std::uint32_t depth, bool reliable, bool transient_local = false);

}  // namespace quadcosim::io
