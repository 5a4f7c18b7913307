#include "dds/ros_types.hpp"

#include <cstddef>
#include <cstring>
#include <map>
#include <stdexcept>
#include <string>

#include "dds/graph.hpp"
#include "dds/idl_walk.hpp"
#include "geometry_msgs.h"
#include "quadcosim_msgs.h"
#include "rosgraph_msgs.h"
#include "sensor_msgs.h"
#include "sim/level_messages.hpp"
#include "sim/messages.hpp"
#include "std_msgs.h"
#include "tf2_msgs.h"

namespace quadcosim::dds {

namespace {

using idl_walk::Arena;
using idl_walk::Mode;
using idl_walk::Walk;

static_assert(sizeof(idl_walk::CSeq) == sizeof(dds_sequence_double) &&
                  offsetof(idl_walk::CSeq, _length) == offsetof(dds_sequence_double, _length) &&
                  offsetof(idl_walk::CSeq, _buffer) == offsetof(dds_sequence_double, _buffer) &&
                  offsetof(idl_walk::CSeq, _release) == offsetof(dds_sequence_double, _release),
              "idlc's sequence layout");

// The idlc type of each message type (its descriptor names the DDS type and holds the instructions).
template <class T>
const dds_topic_descriptor_t& idl();
template <>
const dds_topic_descriptor_t& idl<msg::PoseStamped>() {
  return geometry_msgs_msg_dds__PoseStamped__desc;
}
template <>
const dds_topic_descriptor_t& idl<msg::TwistStamped>() {
  return geometry_msgs_msg_dds__TwistStamped__desc;
}
template <>
const dds_topic_descriptor_t& idl<msg::Imu>() {
  return sensor_msgs_msg_dds__Imu__desc;
}
template <>
const dds_topic_descriptor_t& idl<msg::MagneticField>() {
  return sensor_msgs_msg_dds__MagneticField__desc;
}
template <>
const dds_topic_descriptor_t& idl<msg::FluidPressure>() {
  return sensor_msgs_msg_dds__FluidPressure__desc;
}
template <>
const dds_topic_descriptor_t& idl<msg::NavSatFix>() {
  return sensor_msgs_msg_dds__NavSatFix__desc;
}
template <>
const dds_topic_descriptor_t& idl<msg::Float64MultiArray>() {
  return std_msgs_msg_dds__Float64MultiArray__desc;
}
template <>
const dds_topic_descriptor_t& idl<msg::Clock>() {
  return rosgraph_msgs_msg_dds__Clock__desc;
}
template <>
const dds_topic_descriptor_t& idl<msg::ControllerStatus>() {
  return quadcosim_msgs_msg_dds__ControllerStatus__desc;
}
template <>
const dds_topic_descriptor_t& idl<msg::PlantStatus>() {
  return quadcosim_msgs_msg_dds__PlantStatus__desc;
}
template <>
const dds_topic_descriptor_t& idl<msg::TFMessage>() {
  return tf2_msgs_msg_dds__TFMessage__desc;
}
template <>
const dds_topic_descriptor_t& idl<msg::String>() {
  return std_msgs_msg_dds__String__desc;
}

template <>
const dds_topic_descriptor_t& idl<msg::RotorSpeeds>() {
  return quadcosim_msgs_msg_dds__RotorSpeeds__desc;
}
template <>
const dds_topic_descriptor_t& idl<msg::RotorThrusts>() {
  return quadcosim_msgs_msg_dds__RotorThrusts__desc;
}
template <>
const dds_topic_descriptor_t& idl<msg::ThrustRates>() {
  return quadcosim_msgs_msg_dds__ThrustRates__desc;
}
template <>
const dds_topic_descriptor_t& idl<msg::ThrustAttitude>() {
  return quadcosim_msgs_msg_dds__ThrustAttitude__desc;
}
template <>
const dds_topic_descriptor_t& idl<msg::ThrustTorque>() {
  return quadcosim_msgs_msg_dds__ThrustTorque__desc;
}
template <>
const dds_topic_descriptor_t& idl<msg::VelocityYaw>() {
  return quadcosim_msgs_msg_dds__VelocityYaw__desc;
}
template <>
const dds_topic_descriptor_t& idl<msg::AccelerationYaw>() {
  return quadcosim_msgs_msg_dds__AccelerationYaw__desc;
}

// Room for the C sample of any message type on the stack (checked per type by ops_for).
constexpr std::size_t kMaxSample = 1024;

template <class T>
TypeOps ops_for() {
  const dds_topic_descriptor_t& d = idl<T>();
  if (demangle_ros_type(d.m_typename) != T::kRosType) {
    throw std::logic_error("ros_types: " + std::string(T::kRosType) + " is paired with the idlc type " + d.m_typename);
  }
  if (d.m_size > kMaxSample || d.m_align > alignof(std::max_align_t)) {
    throw std::logic_error("ros_types: the C sample of " + std::string(d.m_typename) + " is larger than kMaxSample");
  }
  idl_walk::check_fields<T>(d);
  return TypeOps{&d,
                 [](dds_entity_t writer, const void* message) -> dds_return_t {
                   alignas(std::max_align_t) unsigned char sample[kMaxSample];  // every member gets written
                   Arena arena;
                   Walk<Mode::kToC> w(T::kRosType, idl<T>().m_ops, sample, &arena);
                   T::fields(*static_cast<const T*>(message), w);
                   w.end();
                   return dds_write(writer, sample);
                 },
                 [](const void* sample, const std::function<void(const void*)>& to) {
                   T m;
                   Walk<Mode::kFromC> w(T::kRosType, idl<T>().m_ops, static_cast<const unsigned char*>(sample),
                                        nullptr);
                   T::fields(m, w);
                   w.end();
                   to(&m);
                 }};
}

}  // namespace

const TypeOps* type_ops(std::type_index type) {
  static const std::map<std::type_index, TypeOps> table = {
      {typeid(msg::PoseStamped), ops_for<msg::PoseStamped>()},
      {typeid(msg::TwistStamped), ops_for<msg::TwistStamped>()},
      {typeid(msg::Imu), ops_for<msg::Imu>()},
      {typeid(msg::MagneticField), ops_for<msg::MagneticField>()},
      {typeid(msg::FluidPressure), ops_for<msg::FluidPressure>()},
      {typeid(msg::NavSatFix), ops_for<msg::NavSatFix>()},
      {typeid(msg::Float64MultiArray), ops_for<msg::Float64MultiArray>()},
      {typeid(msg::Clock), ops_for<msg::Clock>()},
      {typeid(msg::ControllerStatus), ops_for<msg::ControllerStatus>()},
      {typeid(msg::PlantStatus), ops_for<msg::PlantStatus>()},
      {typeid(msg::RotorSpeeds), ops_for<msg::RotorSpeeds>()},
      {typeid(msg::RotorThrusts), ops_for<msg::RotorThrusts>()},
      {typeid(msg::ThrustRates), ops_for<msg::ThrustRates>()},
      {typeid(msg::ThrustAttitude), ops_for<msg::ThrustAttitude>()},
      {typeid(msg::ThrustTorque), ops_for<msg::ThrustTorque>()},
      {typeid(msg::VelocityYaw), ops_for<msg::VelocityYaw>()},
      {typeid(msg::AccelerationYaw), ops_for<msg::AccelerationYaw>()},
      {typeid(msg::TFMessage), ops_for<msg::TFMessage>()},
      {typeid(msg::String), ops_for<msg::String>()},
  };
  const auto it = table.find(type);
  return it == table.end() ? nullptr : &it->second;
}

}  // namespace quadcosim::dds
