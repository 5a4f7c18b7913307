// The messages the nodes exchange, shaped field for field like their ROS 2 types (see
// docs/ros2-wire.md in the shared docs), so a DDS transport maps them one to one and the in-process
// transport carries exactly the numbers the wire would.
#pragma once

#include <array>
#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

namespace quadcosim::msg {

/// builtin_interfaces/msg/Time
struct Time {
  std::int32_t sec = 0;
  std::uint32_t nanosec = 0;

  static Time from_ns(std::int64_t ns);
  std::int64_t to_ns() const { return std::int64_t{sec} * 1'000'000'000 + nanosec; }
};

/// std_msgs/msg/Header
struct Header {
  Time stamp;
  std::string frame_id;
};

struct Vector3 {
  double x = 0, y = 0, z = 0;
};
struct Quaternion {
  double x = 0, y = 0, z = 0, w = 1;
};

/// geometry_msgs/msg/PoseStamped: position in the world frame, orientation q_WB.
struct PoseStamped {
  static constexpr std::string_view kRosType = "geometry_msgs/msg/PoseStamped";
  Header header;
  Vector3 position;  // geometry_msgs/Point
  Quaternion orientation;
};

/// geometry_msgs/msg/TwistStamped: linear velocity in the world frame, angular velocity in body.
struct TwistStamped {
  static constexpr std::string_view kRosType = "geometry_msgs/msg/TwistStamped";
  Header header;
  Vector3 linear;
  Vector3 angular;
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
};

/// std_msgs/msg/MultiArrayDimension
struct MultiArrayDimension {
  std::string label;
  std::uint32_t size = 0;
  std::uint32_t stride = 0;
};

/// std_msgs/msg/Float64MultiArray
struct Float64MultiArray {
  static constexpr std::string_view kRosType = "std_msgs/msg/Float64MultiArray";
  std::vector<double> data;
  std::vector<MultiArrayDimension> dim;  ///< layout.dim
  std::uint32_t data_offset = 0;         ///< layout.data_offset
};

/// Motor commands from quadcosim's controller carry one dimension labelled "rotors@<ns>": the
/// simulated time [ns] of the sensor data the command answers. Lockstep uses it to match commands to
/// ticks; commands without it (any other ROS 2 controller) are matched by arrival.
std::string command_label(std::int64_t stamp_ns);
/// The same label written into `label`, reusing its storage (no allocation once it has held one).
void write_command_label(std::string& label, std::int64_t stamp_ns);
/// The stamp of a command's label, or -1 when it has none.
std::int64_t command_stamp_ns(const Float64MultiArray& m);

/// quadcosim_msgs/msg/ControllerStatus: what the controller decided in one step (for recording and
/// monitoring). Published by the controller after every step, before its motor command.
struct ControllerStatus {
  static constexpr std::string_view kRosType = "quadcosim_msgs/msg/ControllerStatus";
  Header header;                    ///< stamp: the (simulated) time of the step
  std::string mode;                 ///< "attitude" | "position"
  std::array<double, 6> setpoint{};  ///< x, y, z [m], roll, pitch, yaw [rad] actually tracked
  std::array<double, 4> u{};        ///< U1 [N], U2..U4 [N m] requested
  std::array<double, 4> error{};    ///< e_z [m], e_roll, e_pitch, e_yaw [rad]
  std::array<bool, 4> rotor_saturated{};
  bool tilt_saturated = false;
  bool safety = false;              ///< the stale-data safety command was sent
  /// Sensor messages refused so far, by reason (sim/validation.hpp, docs/reliability.md); a refused
  /// message leaves the estimate as it was, so its age grows until the safety command takes over.
  std::uint64_t rejected_non_finite = 0;       ///< NaN/Inf in a field
  std::uint64_t rejected_bad_quaternion = 0;   ///< orientation not a unit quaternion (zero included)
  std::uint64_t rejected_bad_stamp = 0;        ///< sec < 0 or nanosec >= 1e9
  std::uint64_t rejected_stamp_backwards = 0;  ///< older than the newest accepted on its topic
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
  std::string last_problem;  ///< why the newest rejected or clamped command was ("" for none yet)
  bool watchdog_active = false;      ///< the watchdog's policy sets the motors (no valid command for its limit)
  std::uint64_t watchdog_trips = 0;  ///< times the watchdog took over
  std::uint64_t watchdog_ticks = 0;  ///< ticks latched under the watchdog's policy
};

/// rosgraph_msgs/msg/Clock
struct Clock {
  static constexpr std::string_view kRosType = "rosgraph_msgs/msg/Clock";
  Time clock;
};

}  // namespace quadcosim::msg
