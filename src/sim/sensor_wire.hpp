// The wire side of the plant's extra sensors: for each kind of sensors/registry.hpp, its topics and
// messages and how a sample fills them. The channels that publish (sim/sensor_channels.hpp), the MCAP
// recorder and topic listings are derived from this file; sampling is the sensor suite's
// (sensors/suite.hpp), which knows no messages.
//
// Topic names follow the paper's (/drone/Pose, /drone/Imu): the message type's name under the vehicle's
// namespace. Header stamps are the publication tick (as for Pose, Velocity, Imu); frames: body data in
// base_link, world data (the GNSS velocity) in the plant's world frame.
#pragma once

#include <cmath>
#include <numbers>
#include <string>
#include <tuple>
#include <type_traits>
#include <utility>

#include "sensors/registry.hpp"
#include "sim/clock.hpp"
#include "sim/messages.hpp"
#include "sim/transport.hpp"

namespace quadcosim::sim {

namespace sensor_wire {

inline msg::Vector3 vector3(const Eigen::Vector3d& v) { return {v.x(), v.y(), v.z()}; }

struct Magnetometer {
  using Kind = sensors::MagnetometerKind;
  /// Calls f.template operator()<Message>(topic) for each of its topics.
  template <class F>
  static void topics(const std::string& ns, F&& f) {
    f.template operator()<msg::MagneticField>(ns + "/MagneticField");
  }
  Publisher<msg::MagneticField> pub;
  msg::MagneticField m;
  Magnetometer(Transport& t, const std::string& ns, const std::string& /*world_frame*/)
      : pub(t.advertise<msg::MagneticField>(ns + "/MagneticField")) {
    m.header.frame_id = "base_link";
  }
  void fill(const sensors::MagnetometerSample& s, const msg::Time& stamp) {
    m.header.stamp = stamp;
    m.magnetic_field = vector3(s.field_B_T);
    m.magnetic_field_covariance = {};
    m.magnetic_field_covariance[0] = m.magnetic_field_covariance[4] = m.magnetic_field_covariance[8] = s.variance_T2;
  }
  void publish() { pub.publish(m); }
};

struct Barometer {
  using Kind = sensors::BarometerKind;
  template <class F>
  static void topics(const std::string& ns, F&& f) {
    f.template operator()<msg::FluidPressure>(ns + "/FluidPressure");
  }
  Publisher<msg::FluidPressure> pub;
  msg::FluidPressure m;
  Barometer(Transport& t, const std::string& ns, const std::string& /*world_frame*/)
      : pub(t.advertise<msg::FluidPressure>(ns + "/FluidPressure")) {
    m.header.frame_id = "base_link";
  }
  void fill(const sensors::BarometerSample& s, const msg::Time& stamp) {
    m.header.stamp = stamp;
    m.fluid_pressure = s.pressure_Pa;
    m.variance = s.variance_Pa2;
  }
  void publish() { pub.publish(m); }
};

struct Gnss {
  using Kind = sensors::GnssKind;
  template <class F>
  static void topics(const std::string& ns, F&& f) {
    f.template operator()<msg::NavSatFix>(ns + "/NavSatFix");
    f.template operator()<msg::TwistStamped>(ns + "/NavSatVelocity");
  }
  Publisher<msg::NavSatFix> fix_pub;
  Publisher<msg::TwistStamped> velocity_pub;
  msg::NavSatFix fix;
  msg::TwistStamped velocity;  ///< linear: the ENU velocity [m/s]; angular: 0
  Gnss(Transport& t, const std::string& ns, const std::string& world_frame)
      : fix_pub(t.advertise<msg::NavSatFix>(ns + "/NavSatFix")),
        velocity_pub(t.advertise<msg::TwistStamped>(ns + "/NavSatVelocity")) {
    fix.header.frame_id = "base_link";
    fix.status.service = msg::NavSatStatus::kServiceGps;
    velocity.header.frame_id = world_frame;
  }
  void fill(const sensors::GnssSample& s, const msg::Time& stamp) {
    constexpr double kDeg = 180.0 / std::numbers::pi;
    fix.header.stamp = stamp;
    fix.status.status = s.fix ? msg::NavSatStatus::kStatusFix : msg::NavSatStatus::kStatusNoFix;
    fix.latitude = s.position.latitude_rad * kDeg;
    fix.longitude = s.position.longitude_rad * kDeg;
    fix.altitude = s.position.height_m;
    fix.position_covariance = {};
    fix.position_covariance[0] = s.position_variance_enu.x();
    fix.position_covariance[4] = s.position_variance_enu.y();
    fix.position_covariance[8] = s.position_variance_enu.z();
    fix.position_covariance_type =
        s.fix ? msg::NavSatFix::kCovarianceTypeDiagonalKnown : msg::NavSatFix::kCovarianceTypeUnknown;
    velocity.header.stamp = stamp;
    velocity.linear = vector3(s.velocity_W);
    velocity.angular = {};
  }
  void publish() {
    fix_pub.publish(fix);
    velocity_pub.publish(velocity);
  }
};

}  // namespace sensor_wire

/// The wire form of each kind, in the registry's order.
using Wires = std::tuple<sensor_wire::Magnetometer, sensor_wire::Barometer, sensor_wire::Gnss>;
static_assert(std::tuple_size_v<Wires> == std::tuple_size_v<sensors::Kinds>,
              "sim::Wires lists a wire form per sensors::Kinds entry");

/// Calls f.template operator()<Wire>(config) for each sensor `set` configures, in the registry's order.
template <class F>
void for_each_sensor(const sensors::SensorSet& set, F&& f) {
  [&]<std::size_t... I>(std::index_sequence<I...>) {
    (
        [&] {
          using Wire = std::tuple_element_t<I, Wires>;
          static_assert(std::is_same_v<typename Wire::Kind, std::tuple_element_t<I, sensors::Kinds>>,
                        "sim::Wires lists the wire forms in the order of sensors::Kinds");
          if (const auto& c = Wire::Kind::config(set)) f.template operator()<Wire>(*c);
        }(),
        ...);
  }
  (std::make_index_sequence<std::tuple_size_v<Wires>>{});
}

/// Calls f.template operator()<Message>(topic) for each topic the sensors of `set` publish under `ns`.
template <class F>
void for_each_sensor_topic(const sensors::SensorSet& set, const std::string& ns, F&& f) {
  for_each_sensor(set, [&]<class Wire>(const auto&) { Wire::topics(ns, f); });
}

}  // namespace quadcosim::sim
