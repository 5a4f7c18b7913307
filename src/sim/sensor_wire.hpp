// The wire side of the plant's extra sensors: for each kind of sensors/registry.hpp, its topics and
// messages, how a sample fills them (the plant's side) and how a controller reads the sample back
// from them (the controller node's side). The channels that publish (sim/sensor_channels.hpp), the
// controller node's subscriptions, the MCAP recorder and topic listings are derived from this file;
// sampling is the sensor suite's (sensors/suite.hpp), which knows no messages.
//
// Topic names follow the paper's (/drone/Pose, /drone/Imu): the message type's name under the vehicle's
// namespace. Header stamps are the publication tick (as for Pose, Velocity, Imu); frames: body data in
// base_link, world data (the GNSS velocity) in the plant's world frame. What a message has no field
// for (the barometer's temperature, the GNSS velocity's variance) reads back as NaN.
#pragma once

#include <array>
#include <cmath>
#include <limits>
#include <numbers>
#include <string>
#include <string_view>
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
inline Eigen::Vector3d vector3(const msg::Vector3& v) { return {v.x, v.y, v.z}; }
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
constexpr double kDeg = 180.0 / std::numbers::pi;

// Each wire form: Kind (its registry entry), Messages (its message types), kTopics (their names under
// the namespace, in that order), init (what is set once: frame ids), fill (a sample into the messages)
// and read (each message back into the sample, as a controller takes it).

struct Magnetometer {
  using Kind = sensors::MagnetometerKind;
  using Messages = std::tuple<msg::MagneticField>;
  static constexpr std::array<std::string_view, 1> kTopics{"MagneticField"};
  static void init(Messages& m, const std::string& /*world_frame*/) { std::get<0>(m).header.frame_id = "base_link"; }
  static void fill(const Kind::Sample& s, const msg::Time& stamp, Messages& ms) {
    msg::MagneticField& m = std::get<0>(ms);
    m.header.stamp = stamp;
    m.magnetic_field = vector3(s.field_B_T);
    m.magnetic_field_covariance = {};
    m.magnetic_field_covariance[0] = m.magnetic_field_covariance[4] = m.magnetic_field_covariance[8] = s.variance_T2;
  }
  static void read(const msg::MagneticField& m, Kind::Sample& s, const Kind::Config& /*config*/) {
    s.field_B_T = vector3(m.magnetic_field);
    s.variance_T2 = m.magnetic_field_covariance[0];
  }
};

struct Barometer {
  using Kind = sensors::BarometerKind;
  using Messages = std::tuple<msg::FluidPressure>;
  static constexpr std::array<std::string_view, 1> kTopics{"FluidPressure"};
  static void init(Messages& m, const std::string& /*world_frame*/) { std::get<0>(m).header.frame_id = "base_link"; }
  static void fill(const Kind::Sample& s, const msg::Time& stamp, Messages& ms) {
    msg::FluidPressure& m = std::get<0>(ms);
    m.header.stamp = stamp;
    m.fluid_pressure = s.pressure_Pa;
    m.variance = s.variance_Pa2;
  }
  /// The pressure altitude is the model's formula on the reading (the same number the plant computed).
  static void read(const msg::FluidPressure& m, Kind::Sample& s, const Kind::Config& config) {
    s.pressure_Pa = m.fluid_pressure;
    s.variance_Pa2 = m.variance;
    s.altitude_m = sensors::isa_pressure_altitude(m.fluid_pressure, config.sea_level_pressure_Pa);
    s.temperature_K = kNaN;
  }
};

struct Gnss {
  using Kind = sensors::GnssKind;
  /// The fix, and the velocity (linear: ENU [m/s]; angular: 0).
  using Messages = std::tuple<msg::NavSatFix, msg::TwistStamped>;
  static constexpr std::array<std::string_view, 2> kTopics{"NavSatFix", "NavSatVelocity"};
  static void init(Messages& m, const std::string& world_frame) {
    std::get<0>(m).header.frame_id = "base_link";
    std::get<0>(m).status.service = msg::NavSatStatus::kServiceGps;
    std::get<1>(m).header.frame_id = world_frame;
  }
  static void fill(const Kind::Sample& s, const msg::Time& stamp, Messages& ms) {
    msg::NavSatFix& fix = std::get<0>(ms);
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
    msg::TwistStamped& velocity = std::get<1>(ms);
    velocity.header.stamp = stamp;
    velocity.linear = vector3(s.velocity_W);
    velocity.angular = {};
  }
  /// A fix is any status from FIX (0) up (SBAS, GBAS fixes included).
  static void read(const msg::NavSatFix& m, Kind::Sample& s, const Kind::Config& /*config*/) {
    s.fix = m.status.status >= msg::NavSatStatus::kStatusFix;
    s.position.latitude_rad = m.latitude / kDeg;
    s.position.longitude_rad = m.longitude / kDeg;
    s.position.height_m = m.altitude;
    s.position_variance_enu = {m.position_covariance[0], m.position_covariance[4], m.position_covariance[8]};
  }
  static void read(const msg::TwistStamped& m, Kind::Sample& s, const Kind::Config& /*config*/) {
    s.velocity_W = vector3(m.linear);
    s.velocity_variance = kNaN;
  }
};

}  // namespace sensor_wire

/// The wire form of each kind, in the registry's order.
using Wires = std::tuple<sensor_wire::Magnetometer, sensor_wire::Barometer, sensor_wire::Gnss>;
static_assert(std::tuple_size_v<Wires> == std::tuple_size_v<sensors::Kinds>,
              "sim::Wires lists a wire form per sensors::Kinds entry");

/// The wire form of Kind (Wires lists them in the registry's order).
template <class Kind>
using WireOf = std::tuple_element_t<sensors::kind_index<Kind>(), Wires>;

/// Calls f.template operator()<I, Message>(topic) for each message of Wire, with its topic under `ns`.
template <class Wire, class F>
void for_each_message(const std::string& ns, F&& f) {
  [&]<std::size_t... I>(std::index_sequence<I...>) {
    (f.template operator()<I, std::tuple_element_t<I, typename Wire::Messages>>(ns + "/" +
                                                                                std::string(Wire::kTopics[I])),
     ...);
  }
  (std::make_index_sequence<std::tuple_size_v<typename Wire::Messages>>{});
}

/// Calls f.template operator()<Wire>(config) for each sensor `set` configures, in the registry's order.
template <class F>
void for_each_sensor(const sensors::SensorSet& set, F&& f) {
  [&]<std::size_t... I>(std::index_sequence<I...>) {
    (
        [&] {
          using Wire = std::tuple_element_t<I, Wires>;
          static_assert(std::is_same_v<typename Wire::Kind, std::tuple_element_t<I, sensors::Kinds>>,
                        "sim::Wires lists the wire forms in the order of sensors::Kinds");
          static_assert(std::tuple_size_v<typename Wire::Messages> == Wire::kTopics.size(),
                        "a wire form names one topic per message");
          if (const auto& c = Wire::Kind::config(set)) f.template operator()<Wire>(*c);
        }(),
        ...);
  }
  (std::make_index_sequence<std::tuple_size_v<Wires>>{});
}

/// Calls f.template operator()<Message>(topic) for each topic the sensors of `set` publish under `ns`.
template <class F>
void for_each_sensor_topic(const sensors::SensorSet& set, const std::string& ns, F&& f) {
  for_each_sensor(set, [&]<class Wire>(const auto&) {
    for_each_message<Wire>(
        ns, [&]<std::size_t, class Message>(const std::string& topic) { f.template operator()<Message>(topic); });
  });
}

/// The sample a controller reads from the messages `s` fills: what the controller node takes in (the
/// bus) and what Batch hands a vehicle's controller core directly (no bus), the same numbers.
template <class Kind>
typename Kind::Sample as_read(const typename Kind::Sample& s, const typename Kind::Config& config) {
  using Wire = WireOf<Kind>;
  static_assert(std::is_same_v<typename Wire::Kind, Kind>, "sim::Wires lists the wire forms in the registry's order");
  typename Wire::Messages messages;
  Wire::fill(s, msg::Time{}, messages);
  typename Kind::Sample out{};
  std::apply([&](const auto&... m) { (Wire::read(m, out, config), ...); }, messages);
  return out;
}

}  // namespace quadcosim::sim
