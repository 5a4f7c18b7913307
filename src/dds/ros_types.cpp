#include "dds/ros_types.hpp"

#include <map>
#include <type_traits>
#include <vector>

#include "geometry_msgs.h"
#include "quadcosim_msgs.h"
#include "rosgraph_msgs.h"
#include "sensor_msgs.h"
#include "sim/messages.hpp"
#include "std_msgs.h"

namespace quadcosim::dds {

namespace {

// Outgoing C structs borrow the C++ message's memory (strings, sequence buffers): dds_write
// serialises before it returns, so nothing outlives the call.
char* borrow(const std::string& s) { return const_cast<char*>(s.c_str()); }
std::string own(const char* s) { return s ? std::string(s) : std::string(); }

void to_c(const msg::Time& m, builtin_interfaces_msg_dds__Time_& c) {
  c.sec = m.sec;
  c.nanosec = m.nanosec;
}
void from_c(const builtin_interfaces_msg_dds__Time_& c, msg::Time& m) {
  m.sec = c.sec;
  m.nanosec = c.nanosec;
}
void to_c(const msg::Header& m, std_msgs_msg_dds__Header_& c) {
  to_c(m.stamp, c.stamp);
  c.frame_id = borrow(m.frame_id);
}
void from_c(const std_msgs_msg_dds__Header_& c, msg::Header& m) {
  from_c(c.stamp, m.stamp);
  m.frame_id = own(c.frame_id);
}
template <class C>
void to_c3(const msg::Vector3& m, C& c) {
  c.x = m.x;
  c.y = m.y;
  c.z = m.z;
}
template <class C>
void from_c3(const C& c, msg::Vector3& m) {
  m = {c.x, c.y, c.z};
}
void to_c(const msg::Quaternion& m, geometry_msgs_msg_dds__Quaternion_& c) {
  c.x = m.x;
  c.y = m.y;
  c.z = m.z;
  c.w = m.w;
}
void from_c(const geometry_msgs_msg_dds__Quaternion_& c, msg::Quaternion& m) { m = {c.x, c.y, c.z, c.w}; }
template <std::size_t N>
void copy(const double (&from)[N], std::array<double, N>& to) {
  for (std::size_t i = 0; i < N; ++i) to[i] = from[i];
}
template <std::size_t N>
void copy(const std::array<double, N>& from, double (&to)[N]) {
  for (std::size_t i = 0; i < N; ++i) to[i] = from[i];
}

// One specialisation per message type: its C type, descriptor and conversions.
template <class T>
struct Wire;

template <>
struct Wire<msg::PoseStamped> {
  using C = geometry_msgs_msg_dds__PoseStamped_;
  static const dds_topic_descriptor_t* desc() { return &geometry_msgs_msg_dds__PoseStamped__desc; }
  static void to(const msg::PoseStamped& m, C& c) {
    to_c(m.header, c.header);
    to_c3(m.position, c.pose.position);
    to_c(m.orientation, c.pose.orientation);
  }
  static void from(const C& c, msg::PoseStamped& m) {
    from_c(c.header, m.header);
    from_c3(c.pose.position, m.position);
    from_c(c.pose.orientation, m.orientation);
  }
};

template <>
struct Wire<msg::TwistStamped> {
  using C = geometry_msgs_msg_dds__TwistStamped_;
  static const dds_topic_descriptor_t* desc() { return &geometry_msgs_msg_dds__TwistStamped__desc; }
  static void to(const msg::TwistStamped& m, C& c) {
    to_c(m.header, c.header);
    to_c3(m.linear, c.twist.linear);
    to_c3(m.angular, c.twist.angular);
  }
  static void from(const C& c, msg::TwistStamped& m) {
    from_c(c.header, m.header);
    from_c3(c.twist.linear, m.linear);
    from_c3(c.twist.angular, m.angular);
  }
};

template <>
struct Wire<msg::Imu> {
  using C = sensor_msgs_msg_dds__Imu_;
  static const dds_topic_descriptor_t* desc() { return &sensor_msgs_msg_dds__Imu__desc; }
  static void to(const msg::Imu& m, C& c) {
    to_c(m.header, c.header);
    to_c(m.orientation, c.orientation);
    copy(m.orientation_covariance, c.orientation_covariance);
    to_c3(m.angular_velocity, c.angular_velocity);
    copy(m.angular_velocity_covariance, c.angular_velocity_covariance);
    to_c3(m.linear_acceleration, c.linear_acceleration);
    copy(m.linear_acceleration_covariance, c.linear_acceleration_covariance);
  }
  static void from(const C& c, msg::Imu& m) {
    from_c(c.header, m.header);
    from_c(c.orientation, m.orientation);
    copy(c.orientation_covariance, m.orientation_covariance);
    from_c3(c.angular_velocity, m.angular_velocity);
    copy(c.angular_velocity_covariance, m.angular_velocity_covariance);
    from_c3(c.linear_acceleration, m.linear_acceleration);
    copy(c.linear_acceleration_covariance, m.linear_acceleration_covariance);
  }
};

template <>
struct Wire<msg::Float64MultiArray> {
  using C = std_msgs_msg_dds__Float64MultiArray_;
  static const dds_topic_descriptor_t* desc() { return &std_msgs_msg_dds__Float64MultiArray__desc; }
  // Holds the C view of the dimensions while dds_write runs (at most a few; one in practice).
  static void to(const msg::Float64MultiArray& m, C& c, std::vector<std_msgs_msg_dds__MultiArrayDimension_>& dims) {
    dims.resize(m.dim.size());
    for (std::size_t i = 0; i < m.dim.size(); ++i) {
      dims[i] = {borrow(m.dim[i].label), m.dim[i].size, m.dim[i].stride};
    }
    const auto nd = static_cast<uint32_t>(dims.size());
    c.layout.dim = {nd, nd, dims.empty() ? nullptr : dims.data(), false};
    c.layout.data_offset = m.data_offset;
    const auto n = static_cast<uint32_t>(m.data.size());
    c.data = {n, n, const_cast<double*>(m.data.data()), false};
  }
  static void from(const C& c, msg::Float64MultiArray& m) {
    m.data.assign(c.data._buffer, c.data._buffer + c.data._length);
    m.dim.resize(c.layout.dim._length);
    for (std::uint32_t i = 0; i < c.layout.dim._length; ++i) {
      const auto& d = c.layout.dim._buffer[i];
      m.dim[i] = {own(d.label), d.size, d.stride};
    }
    m.data_offset = c.layout.data_offset;
  }
};

template <>
struct Wire<msg::Clock> {
  using C = rosgraph_msgs_msg_dds__Clock_;
  static const dds_topic_descriptor_t* desc() { return &rosgraph_msgs_msg_dds__Clock__desc; }
  static void to(const msg::Clock& m, C& c) { to_c(m.clock, c.clock); }
  static void from(const C& c, msg::Clock& m) { from_c(c.clock, m.clock); }
};

template <>
struct Wire<msg::ControllerStatus> {
  using C = quadcosim_msgs_msg_dds__ControllerStatus_;
  static const dds_topic_descriptor_t* desc() { return &quadcosim_msgs_msg_dds__ControllerStatus__desc; }
  static void to(const msg::ControllerStatus& m, C& c) {
    to_c(m.header, c.header);
    c.mode = borrow(m.mode);
    copy(m.setpoint, c.setpoint);
    copy(m.u, c.u);
    copy(m.error, c.error);
    for (int i = 0; i < 4; ++i) c.rotor_saturated[i] = m.rotor_saturated[i];
    c.tilt_saturated = m.tilt_saturated;
    c.safety = m.safety;
    c.rejected_non_finite = m.rejected_non_finite;
    c.rejected_bad_quaternion = m.rejected_bad_quaternion;
    c.rejected_bad_stamp = m.rejected_bad_stamp;
    c.rejected_stamp_backwards = m.rejected_stamp_backwards;
  }
  static void from(const C& c, msg::ControllerStatus& m) {
    from_c(c.header, m.header);
    m.mode = own(c.mode);
    copy(c.setpoint, m.setpoint);
    copy(c.u, m.u);
    copy(c.error, m.error);
    for (int i = 0; i < 4; ++i) m.rotor_saturated[i] = c.rotor_saturated[i];
    m.tilt_saturated = c.tilt_saturated;
    m.safety = c.safety;
    m.rejected_non_finite = c.rejected_non_finite;
    m.rejected_bad_quaternion = c.rejected_bad_quaternion;
    m.rejected_bad_stamp = c.rejected_bad_stamp;
    m.rejected_stamp_backwards = c.rejected_stamp_backwards;
  }
};

template <>
struct Wire<msg::PlantStatus> {
  using C = quadcosim_msgs_msg_dds__PlantStatus_;
  static const dds_topic_descriptor_t* desc() { return &quadcosim_msgs_msg_dds__PlantStatus__desc; }
  static void to(const msg::PlantStatus& m, C& c) {
    to_c(m.header, c.header);
    c.commands_accepted = m.commands_accepted;
    c.commands_clamped = m.commands_clamped;
    c.commands_rejected_length = m.commands_rejected_length;
    c.commands_rejected_non_finite = m.commands_rejected_non_finite;
    c.last_problem = borrow(m.last_problem);
  }
  static void from(const C& c, msg::PlantStatus& m) {
    from_c(c.header, m.header);
    m.commands_accepted = c.commands_accepted;
    m.commands_clamped = c.commands_clamped;
    m.commands_rejected_length = c.commands_rejected_length;
    m.commands_rejected_non_finite = c.commands_rejected_non_finite;
    m.last_problem = own(c.last_problem);
  }
};

template <class T>
TypeOps ops_for() {
  return TypeOps{
      Wire<T>::desc(),
      [](dds_entity_t writer, const void* message) -> dds_return_t {
        typename Wire<T>::C c{};
        if constexpr (std::is_same_v<T, msg::Float64MultiArray>) {
          std::vector<std_msgs_msg_dds__MultiArrayDimension_> dims;
          Wire<T>::to(*static_cast<const T*>(message), c, dims);
          return dds_write(writer, &c);
        } else {
          Wire<T>::to(*static_cast<const T*>(message), c);
          return dds_write(writer, &c);
        }
      },
      [](const void* sample, const std::function<void(const void*)>& to) {
        T m;
        Wire<T>::from(*static_cast<const typename Wire<T>::C*>(sample), m);
        to(&m);
      }};
}

}  // namespace

const TypeOps* type_ops(std::type_index type) {
  static const std::map<std::type_index, TypeOps> table = {
      {typeid(msg::PoseStamped), ops_for<msg::PoseStamped>()},
      {typeid(msg::TwistStamped), ops_for<msg::TwistStamped>()},
      {typeid(msg::Imu), ops_for<msg::Imu>()},
      {typeid(msg::Float64MultiArray), ops_for<msg::Float64MultiArray>()},
      {typeid(msg::Clock), ops_for<msg::Clock>()},
      {typeid(msg::ControllerStatus), ops_for<msg::ControllerStatus>()},
      {typeid(msg::PlantStatus), ops_for<msg::PlantStatus>()},
  };
  const auto it = table.find(type);
  return it == table.end() ? nullptr : &it->second;
}

}  // namespace quadcosim::dds
