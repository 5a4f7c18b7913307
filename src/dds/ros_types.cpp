#include "dds/ros_types.hpp"

#include <array>
#include <map>
#include <string>
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

// Each message type lists its fields once, as (C++ field, C field) pairs handed to a visitor:
// ToC copies each pair into the C struct, FromC back into the C++ message.
template <class M, class C, class F>
void fields(M& m, C& c, F f) {  // builtin_interfaces/Time
  f(m.sec, c.sec);
  f(m.nanosec, c.nanosec);
}

struct ToC {
  template <class A, class B, std::enable_if_t<std::is_arithmetic_v<A>, int> = 0>
  void operator()(const A& m, B& c) const { c = m; }
  void operator()(const std::string& m, char*& c) const { c = borrow(m); }
  template <class T, std::size_t N>
  void operator()(const std::array<T, N>& m, T (&c)[N]) const {
    for (std::size_t i = 0; i < N; ++i) c[i] = m[i];
  }
  void operator()(const msg::Time& m, builtin_interfaces_msg_dds__Time_& c) const { fields(m, c, *this); }
  void operator()(const msg::Header& m, std_msgs_msg_dds__Header_& c) const {
    (*this)(m.stamp, c.stamp);
    (*this)(m.frame_id, c.frame_id);
  }
  template <class V>  // geometry_msgs Vector3 or Point
  void operator()(const msg::Vector3& m, V& c) const {
    c.x = m.x;
    c.y = m.y;
    c.z = m.z;
  }
  void operator()(const msg::Quaternion& m, geometry_msgs_msg_dds__Quaternion_& c) const {
    c.x = m.x;
    c.y = m.y;
    c.z = m.z;
    c.w = m.w;
  }
};

struct FromC {
  template <class A, class B, std::enable_if_t<std::is_arithmetic_v<A>, int> = 0>
  void operator()(A& m, const B& c) const { m = c; }
  void operator()(std::string& m, const char* c) const { m = own(c); }
  template <class T, std::size_t N>
  void operator()(std::array<T, N>& m, const T (&c)[N]) const {
    for (std::size_t i = 0; i < N; ++i) m[i] = c[i];
  }
  void operator()(msg::Time& m, const builtin_interfaces_msg_dds__Time_& c) const { fields(m, c, *this); }
  void operator()(msg::Header& m, const std_msgs_msg_dds__Header_& c) const {
    (*this)(m.stamp, c.stamp);
    (*this)(m.frame_id, c.frame_id);
  }
  template <class V>
  void operator()(msg::Vector3& m, const V& c) const { m = {c.x, c.y, c.z}; }
  void operator()(msg::Quaternion& m, const geometry_msgs_msg_dds__Quaternion_& c) const { m = {c.x, c.y, c.z, c.w}; }
};

// One specialisation per message type: its C type, descriptor and fields (ops_for below turns them
// into both conversions), or for Float64MultiArray, whose sequences need storage, to and from.
template <class T>
struct Wire;

template <>
struct Wire<msg::PoseStamped> {
  using C = geometry_msgs_msg_dds__PoseStamped_;
  static const dds_topic_descriptor_t* desc() { return &geometry_msgs_msg_dds__PoseStamped__desc; }
  template <class M, class CC, class F>
  static void fields(M& m, CC& c, F f) {
    f(m.header, c.header);
    f(m.position, c.pose.position);
    f(m.orientation, c.pose.orientation);
  }
};

template <>
struct Wire<msg::TwistStamped> {
  using C = geometry_msgs_msg_dds__TwistStamped_;
  static const dds_topic_descriptor_t* desc() { return &geometry_msgs_msg_dds__TwistStamped__desc; }
  template <class M, class CC, class F>
  static void fields(M& m, CC& c, F f) {
    f(m.header, c.header);
    f(m.linear, c.twist.linear);
    f(m.angular, c.twist.angular);
  }
};

template <>
struct Wire<msg::Imu> {
  using C = sensor_msgs_msg_dds__Imu_;
  static const dds_topic_descriptor_t* desc() { return &sensor_msgs_msg_dds__Imu__desc; }
  template <class M, class CC, class F>
  static void fields(M& m, CC& c, F f) {
    f(m.header, c.header);
    f(m.orientation, c.orientation);
    f(m.orientation_covariance, c.orientation_covariance);
    f(m.angular_velocity, c.angular_velocity);
    f(m.angular_velocity_covariance, c.angular_velocity_covariance);
    f(m.linear_acceleration, c.linear_acceleration);
    f(m.linear_acceleration_covariance, c.linear_acceleration_covariance);
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
  template <class M, class CC, class F>
  static void fields(M& m, CC& c, F f) {
    f(m.clock, c.clock);
  }
};

template <>
struct Wire<msg::ControllerStatus> {
  using C = quadcosim_msgs_msg_dds__ControllerStatus_;
  static const dds_topic_descriptor_t* desc() { return &quadcosim_msgs_msg_dds__ControllerStatus__desc; }
  template <class M, class CC, class F>
  static void fields(M& m, CC& c, F f) {
    f(m.header, c.header);
    f(m.mode, c.mode);
    f(m.setpoint, c.setpoint);
    f(m.u, c.u);
    f(m.error, c.error);
    f(m.rotor_saturated, c.rotor_saturated);
    f(m.tilt_saturated, c.tilt_saturated);
    f(m.safety, c.safety);
    f(m.rejected_non_finite, c.rejected_non_finite);
    f(m.rejected_bad_quaternion, c.rejected_bad_quaternion);
    f(m.rejected_bad_stamp, c.rejected_bad_stamp);
    f(m.rejected_stamp_backwards, c.rejected_stamp_backwards);
  }
};

template <>
struct Wire<msg::PlantStatus> {
  using C = quadcosim_msgs_msg_dds__PlantStatus_;
  static const dds_topic_descriptor_t* desc() { return &quadcosim_msgs_msg_dds__PlantStatus__desc; }
  template <class M, class CC, class F>
  static void fields(M& m, CC& c, F f) {
    f(m.header, c.header);
    f(m.commands_accepted, c.commands_accepted);
    f(m.commands_clamped, c.commands_clamped);
    f(m.commands_rejected_length, c.commands_rejected_length);
    f(m.commands_rejected_non_finite, c.commands_rejected_non_finite);
    f(m.last_problem, c.last_problem);
    f(m.watchdog_active, c.watchdog_active);
    f(m.watchdog_trips, c.watchdog_trips);
    f(m.watchdog_ticks, c.watchdog_ticks);
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
          Wire<T>::fields(*static_cast<const T*>(message), c, ToC{});
          return dds_write(writer, &c);
        }
      },
      [](const void* sample, const std::function<void(const void*)>& to) {
        T m;
        const auto& c = *static_cast<const typename Wire<T>::C*>(sample);
        if constexpr (std::is_same_v<T, msg::Float64MultiArray>) {
          Wire<T>::from(c, m);
        } else {
          Wire<T>::fields(m, c, FromC{});
        }
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
