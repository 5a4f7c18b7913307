// Checks on messages that arrive from outside a node (another process, another vehicle, a foreign ROS 2
// node): pure functions of the message and what the node last accepted, so each node only asks and
// counts. What is rejected, clamped and counted, and where it shows: docs/reliability.md.
#pragma once

#include <array>
#include <cstdint>
#include <string>

#include "model/mixer.hpp"
#include "sim/messages.hpp"

namespace quadcosim::sim {

// ---------------------------------------------------------------------------------------------
// Motor commands into the plant

enum class CommandVerdict {
  kAccepted,  ///< four finite speeds in [0, omega_max]: used as sent
  kClamped,   ///< four finite speeds, some negative or above omega_max: used clamped to [0, omega_max]
  kRejected,  ///< wrong length (also empty) or a NaN/Inf entry: ignored, the last good command holds
};

struct CommandCheck {
  CommandVerdict verdict = CommandVerdict::kRejected;
  model::Vector4 omega_rad_s = model::Vector4::Zero();  ///< the speeds to use (not kRejected) [rad/s]
  std::string reason;  ///< why rejected or clamped, naming the entry and value; "" when accepted
};

/// Checks a /<ns>/motor_commands message: `data` must hold exactly 4 finite rotor speeds [rad/s].
/// Finite speeds below 0 become 0 and above `omega_max_rad_s` become omega_max (kClamped). The layout
/// (dim, data_offset) is not checked: it only carries the lockstep label (msg::command_stamp_ns).
CommandCheck validate_command(const msg::Float64MultiArray& m, double omega_max_rad_s);
/// True when validate_command would accept `m` as sent (four finite speeds in [0, omega_max]):
/// asked first on every command, so only a clamped or rejected one builds a CommandCheck.
bool command_ok(const msg::Float64MultiArray& m, double omega_max_rad_s);

// ---------------------------------------------------------------------------------------------
// Sensor messages into the controller

/// Why a sensor message was refused; kNone when it was accepted.
enum class SensorFault {
  kNone,
  kNonFinite,       ///< a NaN or Inf in a field the message carries for the controller
  kBadQuaternion,   ///< orientation norm not within kQuaternionNormTolerance of 1 (zero included)
  kBadStamp,        ///< stamp.sec < 0 or stamp.nanosec >= 1e9: not a ROS time
  kStampBackwards,  ///< stamp older than the newest accepted one on the same topic
};
constexpr int kSensorFaultCount = 5;
const char* to_string(SensorFault f);

/// | |q| - 1 | above this refuses an orientation (tested as |q|^2 within [(1 - tol)^2, (1 + tol)^2],
/// without a square root). The plant sends |q| = 1 to about 1e-15; a sender that normalises in single
/// precision stays within about 1e-7. 1e-3 lets those through and refuses a zero, a
/// default-constructed (0,0,0,0) or a garbled quaternion. Accepted ones are used as sent.
constexpr double kQuaternionNormTolerance = 1e-3;

struct SensorCheck {
  SensorFault fault = SensorFault::kNone;
  std::string reason;  ///< the field and value at fault; "" when accepted
  bool ok() const { return fault == SensorFault::kNone; }
};

/// `last_stamp_ns`: the newest stamp [ns] accepted on this topic, or INT64_MIN before any. A stamp
/// equal to it is accepted (a lockstep peer may repeat a tick's sample); an older one is refused.
/// The content is checked first: kStampBackwards means a well-formed sample that is only too old.
/// Checked: stamp, position and orientation (Pose); stamp, linear and angular (Velocity); stamp,
/// orientation, angular_velocity, linear_acceleration (Imu). Covariances and frame_id are not read.
SensorCheck validate_pose(const msg::PoseStamped& m, std::int64_t last_stamp_ns);
SensorCheck validate_velocity(const msg::TwistStamped& m, std::int64_t last_stamp_ns);
SensorCheck validate_imu(const msg::Imu& m, std::int64_t last_stamp_ns);
/// The same acceptance tests as plain booleans (true: the validate_* function would accept): asked
/// first on every sample, so only a refused one builds a SensorCheck with its reason.
bool pose_ok(const msg::PoseStamped& m, std::int64_t last_stamp_ns);
bool velocity_ok(const msg::TwistStamped& m, std::int64_t last_stamp_ns);
bool imu_ok(const msg::Imu& m, std::int64_t last_stamp_ns);

/// A sender whose clock restarted (a plant process started again under a running controller) sends
/// only well-formed samples older than the newest accepted. After this many such samples in a row
/// on one topic, with none accepted in between, the next one is taken as a restart of the sender's
/// clock and accepted (at 100 Hz: half a second, during which the stale-data safety holds). A single
/// replayed or reordered old sample is still refused.
constexpr int kStampRestartCount = 50;

// ---------------------------------------------------------------------------------------------
// Logging of rejections

/// Decides which of a repeated event to log: the 1st, then every `every`-th (counted, not timed, so
/// what is logged is the same in lockstep and in-process and no wall clock is read). At the rates
/// here (50-100 Hz) every = 100 is about one line per second of simulated time.
class LogThrottle {
 public:
  explicit LogThrottle(std::uint64_t every = 100) : every_(every == 0 ? 1 : every) {}
  /// Counts one event; true when this one should be logged.
  bool count() { return (++count_ - 1) % every_ == 0; }
  std::uint64_t total() const { return count_; }

 private:
  std::uint64_t every_;
  std::uint64_t count_ = 0;
};

}  // namespace quadcosim::sim
