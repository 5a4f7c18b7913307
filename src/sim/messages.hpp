// The messages the nodes exchange, shaped field for field like their ROS 2 types (see
// docs/ros2.md, "What is on the wire"), so a DDS transport maps them one to one and the in-process
// transport carries exactly the numbers the wire would.
//
// Each message states its fields once, here, in wire order: `fields(m, v)` hands every field to a
// visitor as v.field("name", member) (v.field("name", member, note) where the ROS type or a .msg
// default differs from what the C++ type says), and a ROS sub-message that has no C++ struct of its
// own (Pose, Twist, MultiArrayLayout) as v.group("name", "pkg/msg/Type", [&](auto& g) { ... }).
// From these lists follow the CDR writer and `.msg` schema text of recordings (io/ros2_cdr.cpp), the YAML that
// `topic echo` prints (dds/topic_tools.hpp) and the copies to and from the C types idlc generates (dds/idl_walk.hpp),
// which walk a list in step with idlc's instructions and refuse, naming it, a field whose type differs or that only
// one side has. A new field: one line here plus its .idl member.
//
// A message whose .msg file declares constants states them once too, as typed members (kStatusFix) that
// `constants(v)` hands over as v.constant("STATUS_FIX", kStatusFix): the .msg schema text of recordings
// lists them, so a reader can name a status; they are neither on the wire nor part of the type hash.
#pragma once

#include <array>
#include <cstdint>
#include <string>
#include <string_view>
#include <type_traits>
#include <vector>

namespace quadcosim::msg {

/// What a field's C++ type does not say: its ROS type when another message shares the C++ struct
/// (geometry_msgs/Point is a Vector3 here), and its default in the .msg file.
struct FieldNote {
  std::string_view ros_type;       ///< "pkg/msg/Type", "" for the C++ type's own
  std::string_view default_value;  ///< .msg default ("0"), "" for none
};

/// For visitors of fields(): whether a field's type is a ROS fixed array (std::array) or sequence
/// (std::vector); a field that is neither, nor a primitive or std::string, is a nested message.
template <class T>
struct IsArray : std::false_type {};
template <class T, std::size_t N>
struct IsArray<std::array<T, N>> : std::true_type {};
template <class T>
struct IsVector : std::false_type {};
template <class T>
struct IsVector<std::vector<T>> : std::true_type {};

/// builtin_interfaces/msg/Time
struct Time {
  static constexpr std::string_view kRosType = "builtin_interfaces/msg/Time";
  std::int32_t sec = 0;
  std::uint32_t nanosec = 0;
  template <class M, class V>
  static void fields(M& m, V& v) {
    v.field("sec", m.sec);
    v.field("nanosec", m.nanosec);
  }

  static Time from_ns(std::int64_t ns);
  std::int64_t to_ns() const { return std::int64_t{sec} * 1'000'000'000 + nanosec; }
};

/// std_msgs/msg/Header
struct Header {
  static constexpr std::string_view kRosType = "std_msgs/msg/Header";
  Time stamp;
  std::string frame_id;
  template <class M, class V>
  static void fields(M& m, V& v) {
    v.field("stamp", m.stamp);
    v.field("frame_id", m.frame_id);
  }
};

/// geometry_msgs/msg/Vector3 (and, by FieldNote, geometry_msgs/msg/Point)
struct Vector3 {
  static constexpr std::string_view kRosType = "geometry_msgs/msg/Vector3";
  double x = 0, y = 0, z = 0;
  template <class M, class V>
  static void fields(M& m, V& v) {
    v.field("x", m.x);
    v.field("y", m.y);
    v.field("z", m.z);
  }
};
inline constexpr FieldNote kPoint{"geometry_msgs/msg/Point", ""};

/// geometry_msgs/msg/Quaternion
struct Quaternion {
  static constexpr std::string_view kRosType = "geometry_msgs/msg/Quaternion";
  double x = 0, y = 0, z = 0, w = 1;
  template <class M, class V>
  static void fields(M& m, V& v) {
    v.field("x", m.x, FieldNote{"", "0"});
    v.field("y", m.y, FieldNote{"", "0"});
    v.field("z", m.z, FieldNote{"", "0"});
    v.field("w", m.w, FieldNote{"", "1"});
  }
};

/// geometry_msgs/msg/PoseStamped: position in the world frame, orientation q_WB.
struct PoseStamped {
  static constexpr std::string_view kRosType = "geometry_msgs/msg/PoseStamped";
  Header header;
  Vector3 position;  // geometry_msgs/Point
  Quaternion orientation;
  template <class M, class V>
  static void fields(M& m, V& v) {
    v.field("header", m.header);
    v.group("pose", "geometry_msgs/msg/Pose", [&](auto& g) {
      g.field("position", m.position, kPoint);
      g.field("orientation", m.orientation);
    });
  }
};

/// geometry_msgs/msg/TwistStamped: linear velocity in the world frame, angular velocity in body.
struct TwistStamped {
  static constexpr std::string_view kRosType = "geometry_msgs/msg/TwistStamped";
  Header header;
  Vector3 linear;
  Vector3 angular;
  template <class M, class V>
  static void fields(M& m, V& v) {
    v.field("header", m.header);
    v.group("twist", "geometry_msgs/msg/Twist", [&](auto& g) {
      g.field("linear", m.linear);
      g.field("angular", m.angular);
    });
  }
};

/// sensor_msgs/msg/Imu: orientation q_WB, body rates, specific force in body.
struct Imu {
  static constexpr std::string_view kRosType = "sensor_msgs/msg/Imu";
  Header header;
  Quaternion orientation;
  std::array<double, 9> orientation_covariance{};
  Vector3 angular_velocity;
  std::array<double, 9> angular_velocity_covariance{};
  Vector3 linear_acceleration;
  std::array<double, 9> linear_acceleration_covariance{};
  template <class M, class V>
  static void fields(M& m, V& v) {
    v.field("header", m.header);
    v.field("orientation", m.orientation);
    v.field("orientation_covariance", m.orientation_covariance);
    v.field("angular_velocity", m.angular_velocity);
    v.field("angular_velocity_covariance", m.angular_velocity_covariance);
    v.field("linear_acceleration", m.linear_acceleration);
    v.field("linear_acceleration_covariance", m.linear_acceleration_covariance);
  }
};

/// sensor_msgs/msg/MagneticField: the field vector [T] in header.frame_id's axes.
struct MagneticField {
  static constexpr std::string_view kRosType = "sensor_msgs/msg/MagneticField";
  Header header;
  Vector3 magnetic_field;                             ///< [T]
  std::array<double, 9> magnetic_field_covariance{};  ///< [T^2], row major x, y, z; all 0: unknown
  template <class M, class V>
  static void fields(M& m, V& v) {
    v.field("header", m.header);
    v.field("magnetic_field", m.magnetic_field);
    v.field("magnetic_field_covariance", m.magnetic_field_covariance);
  }
};

/// sensor_msgs/msg/FluidPressure: an absolute pressure (a barometer's static pressure).
struct FluidPressure {
  static constexpr std::string_view kRosType = "sensor_msgs/msg/FluidPressure";
  Header header;
  double fluid_pressure = 0;  ///< [Pa]
  double variance = 0;        ///< [Pa^2], 0: unknown
  template <class M, class V>
  static void fields(M& m, V& v) {
    v.field("header", m.header);
    v.field("fluid_pressure", m.fluid_pressure);
    v.field("variance", m.variance);
  }
};

/// sensor_msgs/msg/NavSatStatus (Jazzy): the kind of fix and the satellite systems used.
struct NavSatStatus {
  static constexpr std::string_view kRosType = "sensor_msgs/msg/NavSatStatus";
  static constexpr std::int8_t kStatusUnknown = -2;  ///< not yet set
  static constexpr std::int8_t kStatusNoFix = -1;
  static constexpr std::int8_t kStatusFix = 0;         ///< unaugmented
  static constexpr std::int8_t kStatusSbasFix = 1;     ///< satellite-based augmentation
  static constexpr std::int8_t kStatusGbasFix = 2;     ///< ground-based augmentation
  static constexpr std::uint16_t kServiceUnknown = 0;  ///< `service` is a bit set: compare with ==
  static constexpr std::uint16_t kServiceGps = 1;
  static constexpr std::uint16_t kServiceGlonass = 2;
  static constexpr std::uint16_t kServiceCompass = 4;  ///< BeiDou included
  static constexpr std::uint16_t kServiceGalileo = 8;
  std::int8_t status = kStatusUnknown;  // the .msg default
  std::uint16_t service = kServiceUnknown;
  template <class V>
  static void constants(V& v) {
    v.constant("STATUS_UNKNOWN", kStatusUnknown);
    v.constant("STATUS_NO_FIX", kStatusNoFix);
    v.constant("STATUS_FIX", kStatusFix);
    v.constant("STATUS_SBAS_FIX", kStatusSbasFix);
    v.constant("STATUS_GBAS_FIX", kStatusGbasFix);
    v.constant("SERVICE_UNKNOWN", kServiceUnknown);
    v.constant("SERVICE_GPS", kServiceGps);
    v.constant("SERVICE_GLONASS", kServiceGlonass);
    v.constant("SERVICE_COMPASS", kServiceCompass);
    v.constant("SERVICE_GALILEO", kServiceGalileo);
  }
  template <class M, class V>
  static void fields(M& m, V& v) {
    v.field("status", m.status, FieldNote{"", "-2"});
    v.field("service", m.service);
  }
};

/// sensor_msgs/msg/NavSatFix: a GNSS fix on the WGS 84 ellipsoid.
struct NavSatFix {
  static constexpr std::string_view kRosType = "sensor_msgs/msg/NavSatFix";
  static constexpr std::uint8_t kCovarianceTypeUnknown = 0;
  static constexpr std::uint8_t kCovarianceTypeApproximated = 1;
  static constexpr std::uint8_t kCovarianceTypeDiagonalKnown = 2;
  static constexpr std::uint8_t kCovarianceTypeKnown = 3;
  Header header;
  NavSatStatus status;
  double latitude = 0;                          ///< [deg], north positive
  double longitude = 0;                         ///< [deg], east positive
  double altitude = 0;                          ///< [m] above the ellipsoid (NaN: none)
  std::array<double, 9> position_covariance{};  ///< [m^2], East, North, Up, row major
  std::uint8_t position_covariance_type = kCovarianceTypeUnknown;
  template <class V>
  static void constants(V& v) {
    v.constant("COVARIANCE_TYPE_UNKNOWN", kCovarianceTypeUnknown);
    v.constant("COVARIANCE_TYPE_APPROXIMATED", kCovarianceTypeApproximated);
    v.constant("COVARIANCE_TYPE_DIAGONAL_KNOWN", kCovarianceTypeDiagonalKnown);
    v.constant("COVARIANCE_TYPE_KNOWN", kCovarianceTypeKnown);
  }
  template <class M, class V>
  static void fields(M& m, V& v) {
    v.field("header", m.header);
    v.field("status", m.status);
    v.field("latitude", m.latitude);
    v.field("longitude", m.longitude);
    v.field("altitude", m.altitude);
    v.field("position_covariance", m.position_covariance);
    v.field("position_covariance_type", m.position_covariance_type);
  }
};

/// std_msgs/msg/MultiArrayDimension
struct MultiArrayDimension {
  static constexpr std::string_view kRosType = "std_msgs/msg/MultiArrayDimension";
  std::string label;
  std::uint32_t size = 0;
  std::uint32_t stride = 0;
  template <class M, class V>
  static void fields(M& m, V& v) {
    v.field("label", m.label);
    v.field("size", m.size);
    v.field("stride", m.stride);
  }
};

/// std_msgs/msg/Float64MultiArray
struct Float64MultiArray {
  static constexpr std::string_view kRosType = "std_msgs/msg/Float64MultiArray";
  std::vector<double> data;
  std::vector<MultiArrayDimension> dim;  ///< layout.dim
  std::uint32_t data_offset = 0;         ///< layout.data_offset
  template <class M, class V>
  static void fields(M& m, V& v) {
    v.group("layout", "std_msgs/msg/MultiArrayLayout", [&](auto& g) {
      g.field("dim", m.dim);
      g.field("data_offset", m.data_offset);
    });
    v.field("data", m.data);
  }
};

/// Motor commands from quadcosim's controller carry one dimension labelled "rotors@<ns>": the
/// simulated time [ns] of the sensor data the command answers. Lockstep uses it to match commands to
/// ticks; commands without it (any other ROS 2 controller) are matched by arrival.
std::string command_label(std::int64_t stamp_ns);
/// The same label written into `label`, reusing its storage (no allocation once it has held one).
void write_command_label(std::string& label, std::int64_t stamp_ns);
/// The stamp of a command's label, or -1 when it has none.
std::int64_t command_stamp_ns(const Float64MultiArray& m);

/// A command at a level above rotor speeds (control/command_level.hpp: ctbr, velocity, ...) names it in
/// a layout dimension labelled "level=<name>" ("level=ctbr"), after the lockstep label when there is
/// one; `data` then holds that level's values. A command without one is rotor speeds, as always.
inline constexpr std::string_view kCommandLevelPrefix = "level=";
/// The level a command names ("" when it names none: rotor speeds).
std::string_view command_level_name(const Float64MultiArray& m);
/// Names the level in `m`'s layout (dim[1], or dim[0] when it has no lockstep label); "" or
/// "rotor_speeds" removes the level dimension. Reuses the label's storage.
void set_command_level(Float64MultiArray& m, std::string_view name);

/// quadcosim_msgs/msg/ControllerStatus: what the controller decided in one step (for recording and
/// monitoring). Published by the controller node after every step, before its motor command. A generic
/// part that every controller fills (through the node), then the controller's own named figures.
struct ControllerStatus {
  static constexpr std::string_view kRosType = "quadcosim_msgs/msg/ControllerStatus";
  Header header;                           ///< stamp: the (simulated) time of the step
  std::string controller;                  ///< the controller's type ("paper", "se3", ...)
  std::string mode;                        ///< "attitude" | "position"
  std::array<double, 6> setpoint{};        ///< x, y, z [m] of the reference, roll, pitch, yaw [rad] actually tracked
  std::array<double, 4> u{};               ///< U1 [N], U2..U4 [N m] requested
  std::array<double, 3> position_error{};  ///< reference minus observed position [m] (world)
  double yaw_error = 0.0;                  ///< reference minus observed yaw, wrapped to [-pi, pi] [rad]
  /// Psi = 1/2 tr(I - R_d^T R) in [0, 2] for a controller with a desired attitude R_d, NaN otherwise.
  double attitude_error = 0.0;
  /// The allocation clamped rotor i (one entry per rotor of the vehicle; those past its count false).
  std::array<bool, 8> rotor_saturated{};
  bool tilt_saturated = false;
  bool safety = false;  ///< the stale-data safety command was sent
  /// Sensor messages refused so far, by reason (sim/validation.hpp, docs/reliability.md); a refused
  /// message leaves the observation as it was, so its age grows until the safety command takes over.
  std::uint64_t rejected_non_finite = 0;       ///< NaN/Inf in a field
  std::uint64_t rejected_bad_quaternion = 0;   ///< orientation not a unit quaternion (zero included)
  std::uint64_t rejected_bad_stamp = 0;        ///< sec < 0 or nanosec >= 1e9
  std::uint64_t rejected_stamp_backwards = 0;  ///< older than the newest accepted on its topic
  std::uint64_t rejected_stamp_ahead = 0;      ///< further ahead of the newest accepted than sim::kStampAheadLimitNs
  std::vector<std::string> output_names;       ///< the controller's own figures: names ...
  std::vector<double> outputs;                 ///< ... and values (NaN under the safety command)
  template <class M, class V>
  static void fields(M& m, V& v) {
    v.field("header", m.header);
    v.field("controller", m.controller);
    v.field("mode", m.mode);
    v.field("setpoint", m.setpoint);
    v.field("u", m.u);
    v.field("position_error", m.position_error);
    v.field("yaw_error", m.yaw_error);
    v.field("attitude_error", m.attitude_error);
    v.field("rotor_saturated", m.rotor_saturated);
    v.field("tilt_saturated", m.tilt_saturated);
    v.field("safety", m.safety);
    v.field("rejected_non_finite", m.rejected_non_finite);
    v.field("rejected_bad_quaternion", m.rejected_bad_quaternion);
    v.field("rejected_bad_stamp", m.rejected_bad_stamp);
    v.field("rejected_stamp_backwards", m.rejected_stamp_backwards);
    v.field("rejected_stamp_ahead", m.rejected_stamp_ahead);
    v.field("output_names", m.output_names);
    v.field("outputs", m.outputs);
  }
};

/// quadcosim_msgs/msg/PlantStatus: what the plant did with the motor commands it received (counters
/// since start). Published by the plant with its sensor outputs on every tick whose counters changed
/// and otherwise once per simulated second (tick 0 included). Lockstep repeats of an earlier tick's
/// command are not counted here, so the status is the same in-process and over DDS.
struct PlantStatus {
  static constexpr std::string_view kRosType = "quadcosim_msgs/msg/PlantStatus";
  Header header;                                   ///< stamp: the (simulated) time of the tick
  std::uint64_t commands_accepted = 0;             ///< used (clamped ones included)
  std::uint64_t commands_clamped = 0;              ///< a speed < 0 or > omega_max: used clamped
  std::uint64_t commands_rejected_length = 0;      ///< not exactly 4 values (empty included): ignored
  std::uint64_t commands_rejected_non_finite = 0;  ///< a NaN/Inf speed: ignored
  std::string last_problem;                        ///< why the newest rejected or clamped command was ("" for none yet)
  bool watchdog_active = false;        ///< the watchdog's policy sets the motors (no valid command for its limit)
  std::uint64_t watchdog_trips = 0;    ///< times the watchdog took over
  std::uint64_t watchdog_ticks = 0;    ///< ticks latched under the watchdog's policy
  std::uint64_t commands_stale = 0;    ///< lockstep repeats of an answered tick: dropped
  std::uint64_t commands_foreign = 0;  ///< from a writer other than the paired controller's: ignored
  /// On a second command topic (/<ns>/motor_commands, /<ns>/cmd/<level>) for a tick another topic already
  /// commanded (one writer per tick, docs/ros2.md): ignored
  std::uint64_t commands_rejected_second_topic = 0;
  std::uint64_t commands_rejected_bad_quaternion = 0;  ///< ThrustAttitude's attitude not a unit quaternion: ignored
  template <class M, class V>
  static void fields(M& m, V& v) {
    v.field("header", m.header);
    v.field("commands_accepted", m.commands_accepted);
    v.field("commands_clamped", m.commands_clamped);
    v.field("commands_rejected_length", m.commands_rejected_length);
    v.field("commands_rejected_non_finite", m.commands_rejected_non_finite);
    v.field("last_problem", m.last_problem);
    v.field("watchdog_active", m.watchdog_active);
    v.field("watchdog_trips", m.watchdog_trips);
    v.field("watchdog_ticks", m.watchdog_ticks);
    v.field("commands_stale", m.commands_stale);
    v.field("commands_foreign", m.commands_foreign);
    v.field("commands_rejected_second_topic", m.commands_rejected_second_topic);
    v.field("commands_rejected_bad_quaternion", m.commands_rejected_bad_quaternion);
  }
};

/// geometry_msgs/msg/TransformStamped: the pose of frame child_frame_id in frame header.frame_id
/// (translation of its origin, rotation q_parent_child), as tf2 carries it.
struct TransformStamped {
  static constexpr std::string_view kRosType = "geometry_msgs/msg/TransformStamped";
  Header header;
  std::string child_frame_id;
  Vector3 translation;  ///< transform.translation
  Quaternion rotation;  ///< transform.rotation
  template <class M, class V>
  static void fields(M& m, V& v) {
    v.field("header", m.header);
    v.field("child_frame_id", m.child_frame_id);
    v.group("transform", "geometry_msgs/msg/Transform", [&](auto& g) {
      g.field("translation", m.translation);
      g.field("rotation", m.rotation);
    });
  }
};

/// tf2_msgs/msg/TFMessage: what /tf and /tf_static carry.
struct TFMessage {
  static constexpr std::string_view kRosType = "tf2_msgs/msg/TFMessage";
  std::vector<TransformStamped> transforms;
  template <class M, class V>
  static void fields(M& m, V& v) {
    v.field("transforms", m.transforms);
  }
};

/// std_msgs/msg/String (the robot description: a URDF).
struct String {
  static constexpr std::string_view kRosType = "std_msgs/msg/String";
  std::string data;
  template <class M, class V>
  static void fields(M& m, V& v) {
    v.field("data", m.data);
  }
};

/// rosgraph_msgs/msg/Clock
struct Clock {
  static constexpr std::string_view kRosType = "rosgraph_msgs/msg/Clock";
  Time clock;
  template <class M, class V>
  static void fields(M& m, V& v) {
    v.field("clock", m.clock);
  }
};

}  // namespace quadcosim::msg
