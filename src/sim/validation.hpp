// Checks on messages that arrive from outside a node (another process, another vehicle, a foreign ROS 2
// node): pure functions of the message and what the node last accepted, so each node only asks and
// counts. Each acceptance rule is stated once, in one check per message that returns plain data (what
// was wrong, in which field, with which values); the text is formed from it by reason() only when a
// refused or clamped message is recorded or logged. What is rejected, clamped and counted, and where
// it shows: docs/reliability.md.
#pragma once

#include <array>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <string>
#include <string_view>

#include "control/command_level.hpp"
#include "model/mixer.hpp"
#include "sensors/registry.hpp"
#include "sim/messages.hpp"

namespace quadcosim::sim {

// ---------------------------------------------------------------------------------------------
// Motor commands into the plant

enum class CommandVerdict {
  kAccepted,  ///< four finite speeds in [0, omega_max]: used as sent
  kClamped,   ///< four finite speeds, some negative or above omega_max: used clamped to [0, omega_max]
  kRejected,  ///< wrong length (also empty) or a NaN/Inf entry: ignored, the last good command holds
};

/// What was wrong with a motor command; kNone when it was used as sent.
enum class CommandFault : std::uint8_t {
  kNone,
  kWrongLength,         ///< not exactly N rotor speeds (the vehicle's rotor count) or 4 level values (kRejected)
  kNonFinite,           ///< a NaN or Inf speed (kRejected)
  kOutOfRange,          ///< four finite speeds, some < 0 or > omega_max (kClamped); rotor thrusts < 0
  kUnknownLevel,        ///< the layout names a command level quadcosim does not know (kRejected)
  kBadQuaternion,       ///< a ThrustAttitude whose attitude is not a unit quaternion (kRejected)
  kLevelNotForVehicle,  ///< rotor_thrusts for a vehicle without four rotors (kRejected)
};

/// The outcome of check_command: plain data, no allocation; reason() says it in words.
struct CommandCheck {
  CommandFault fault = CommandFault::kNone;
  /// The speeds to use (not kRejected) [rad/s], one per rotor; a level's 4 values.
  model::RotorVector omega_rad_s;  ///< zeros when rejected
  std::size_t values = 4;          ///< how many values the message held
  int rotors = 4;                  ///< the vehicle's rotor count: how many speeds were expected
  int rotor = 0;                   ///< the rotor at fault, 0..3: the first non-finite one, or the first clamped one
  double value = 0.0;              ///< that rotor's speed as sent [rad/s] (kNonFinite, kOutOfRange)
  double omega_max_rad_s = 0.0;    ///< the upper end of the range checked against [rad/s]
  /// The command's level (msg::command_level_name); omega_rad_s then holds that level's 4 values.
  control::CommandLevel level = control::CommandLevel::kRotorSpeeds;
  std::array<char, 24> unknown_level{};  ///< the start of an unknown level's name (kUnknownLevel)
  double quaternion_norm = 1.0;          ///< the attitude's norm as sent (kBadQuaternion)

  CommandVerdict verdict() const;
  /// Why rejected or clamped, naming the rotor (1..4) and its value, e.g. "rotor 2 speed is nan, expected a
  /// finite number" or "rotor 1 speed -5 rad/s clamped to 0 (range [0, 12000])"; "" when accepted.
  std::string reason() const;
};

/// Checks a /<ns>/motor_commands message: `data` must hold exactly `rotor_count` finite rotor speeds
/// [rad/s] (the vehicle's; 4 for a quadrotor).
/// Finite speeds below 0 become 0 and above `omega_max_rad_s` become omega_max (kOutOfRange, kClamped).
/// Checked in this order, the first fault reported: the length, then each speed for NaN/Inf (rotor 1
/// first), then the range. The layout (dim, data_offset) is not checked: it only carries the lockstep
/// label (msg::command_stamp_ns). Allocates nothing.
/// A command whose layout names a level above rotor speeds (msg::command_level_name: "level=ctbr")
/// holds that level's 4 values instead: the level must be known (else kUnknownLevel), the values 4
/// (kWrongLength) and finite (kNonFinite); rotor thrusts below 0 become 0 (kOutOfRange). The plant's
/// inner loops turn it into rotor speeds every tick (control/inner_loops.hpp). rotor_thrusts is a
/// four-rotor level: refused (kLevelNotForVehicle) for another rotor count.
CommandCheck check_command(const msg::Float64MultiArray& m, double omega_max_rad_s, int rotor_count = 4);
/// The same checks for `count` values at `level` (a typed command, msg::level_values: the one rule for
/// both ways of sending a level); rotor speeds `rotor_count` of them. `attitude_norm`: a ThrustAttitude's
/// quaternion norm as sent, refused (kBadQuaternion) when not within kQuaternionNormTolerance of 1,
/// after the values' own checks.
CommandCheck check_command(control::CommandLevel level, const double* values, std::size_t count, double omega_max_rad_s,
                           int rotor_count, double attitude_norm = 1.0);

// ---------------------------------------------------------------------------------------------
// Sensor messages into the controller

/// Why a sensor message was refused; kNone when it was accepted.
enum class SensorFault : std::uint8_t {
  kNone,
  kNonFinite,       ///< a NaN or Inf in a field the message carries for the controller
  kBadQuaternion,   ///< orientation norm not within kQuaternionNormTolerance of 1 (zero included)
  kBadStamp,        ///< stamp.sec < 0 or stamp.nanosec >= 1e9: not a ROS time
  kStampBackwards,  ///< stamp older than the newest accepted one on the same topic
  kStampAhead,      ///< stamp further ahead of the newest accepted one on the same topic than kStampAheadLimitNs
};
constexpr int kSensorFaultCount = 6;

/// A sample stamped more than this [ns] after the newest accepted on its topic is refused: one
/// sample stamped far in the future (a stranger's, a broken clock) would otherwise become the newest
/// and make every genuine sample after it "older than the newest", blinding the controller. Two
/// seconds: more than the period of any sensor the plant simulates, far less than a stale-data limit
/// a controller would survive. A sender whose clock really jumped forward is taken after
/// kStampRestartCount such samples in a row, as a restart is. A controller that measures age on the
/// receipt clock (real time) adds the time since it accepted the newest: a plant whose samples did
/// not reach it for longer (a cut link) has simulated that much further meanwhile.
constexpr std::int64_t kStampAheadLimitNs = 2'000'000'000;
const char* to_string(SensorFault f);

/// The field of a sensor message at fault (its name in the ROS 2 message).
enum class SensorField : std::uint8_t {
  kNone,
  kStamp,               ///< header.stamp
  kPosition,            ///< Pose position
  kOrientation,         ///< Pose or Imu orientation
  kLinear,              ///< Velocity linear
  kAngular,             ///< Velocity angular
  kAngularVelocity,     ///< Imu angular_velocity
  kLinearAcceleration,  ///< Imu linear_acceleration
  kSample,              ///< a column of an extra sensor's sample (SensorCheck::sensor, ::column)
};
const char* to_string(SensorField f);

/// | |q| - 1 | above this refuses an orientation (tested as |q|^2 within [(1 - tol)^2, (1 + tol)^2],
/// without a square root). The plant sends |q| = 1 to about 1e-15; a sender that normalises in single
/// precision stays within about 1e-7. 1e-3 lets those through and refuses a zero, a
/// default-constructed (0,0,0,0) or a garbled quaternion. Accepted ones are used as sent.
constexpr double kQuaternionNormTolerance = 1e-3;

/// The outcome of check_pose, check_velocity or check_imu: plain data, no allocation; reason() says it
/// in words.
struct SensorCheck {
  SensorFault fault = SensorFault::kNone;
  SensorField field = SensorField::kNone;  ///< the field at fault
  /// That field's values as sent: x, y, z of a vector (kNonFinite), x, y, z, w of an orientation
  /// (kNonFinite, kBadQuaternion). Unused for the stamp.
  std::array<double, 4> value{};
  msg::Time stamp;                  ///< the stamp as sent (kBadStamp, kStampBackwards)
  std::int64_t newest_ns = 0;       ///< the newest accepted stamp it is older than, or too far ahead of [ns]
  std::int64_t ahead_limit_ns = 0;  ///< kStampAhead: how far ahead of newest_ns was allowed [ns]
  /// kSample: the sensor's and the column's names ("gnss", "v": sensors/registry.hpp), values in value[0..2].
  std::string_view sensor, column;
  int width = 0;  ///< kSample: the column's numbers (1 or 3)

  bool ok() const { return fault == SensorFault::kNone; }
  /// The field and value at fault and what was expected, e.g. "position (nan, 2, 3): expected finite
  /// values" or "stamp 10 ns is older than the newest accepted, 20 ns"; "" when accepted.
  std::string reason() const;
};

/// `last_stamp_ns`: the newest stamp [ns] accepted on this topic, or INT64_MIN before any. A stamp
/// equal to it is accepted (a lockstep peer may repeat a tick's sample); an older one is refused, and
/// so is one more than `ahead_limit_ns` (kStampAheadLimitNs, or more: see there) newer.
/// Checked in this order, the first fault reported (content first, so kStampBackwards means a
/// well-formed sample that is only too old): Pose position, orientation, stamp; Velocity linear,
/// angular, stamp; Imu orientation, angular_velocity, linear_acceleration, stamp. An orientation is
/// checked for NaN/Inf, then for its norm; a stamp for its form, then its age. Covariances and
/// frame_id are not read. Allocate nothing.
SensorCheck check_pose(const msg::PoseStamped& m, std::int64_t last_stamp_ns,
                       std::int64_t ahead_limit_ns = kStampAheadLimitNs);
SensorCheck check_velocity(const msg::TwistStamped& m, std::int64_t last_stamp_ns,
                           std::int64_t ahead_limit_ns = kStampAheadLimitNs);
SensorCheck check_imu(const msg::Imu& m, std::int64_t last_stamp_ns, std::int64_t ahead_limit_ns = kStampAheadLimitNs);

/// A stamp after the newest accepted on its topic, `last_stamp_ns`: its form, then its age, as above.
SensorCheck check_stamp(const msg::Time& stamp, std::int64_t last_stamp_ns,
                        std::int64_t ahead_limit_ns = kStampAheadLimitNs);

/// A sample of an extra sensor (sensors/registry.hpp) as read from its message(s): each column finite
/// (only the flag of a GNSS sample without a fix: the rest is NaN then), in column order, then its
/// stamp as check_stamp. The field is kSample, naming the sensor and column. Allocates nothing.
template <class Kind>
SensorCheck check_sample(const typename Kind::Sample& sample, const msg::Time& stamp, std::int64_t last_stamp_ns,
                         std::int64_t ahead_limit_ns = kStampAheadLimitNs) {
  double v[sensors::sample_width<Kind>()];
  sensors::write_sample<Kind>(sample, v);
  const bool numbers = sensors::has_numbers<Kind>(sample);
  const double* at = v;
  for (const auto& c : Kind::kColumns) {
    if (numbers || c.boolean) {
      for (int i = 0; i < c.width; ++i) {
        if (std::isfinite(at[i])) continue;
        SensorCheck refused;
        refused.fault = SensorFault::kNonFinite;
        refused.field = SensorField::kSample;
        refused.sensor = Kind::kName;
        refused.column = c.name;
        refused.width = c.width;
        for (int j = 0; j < c.width && j < 3; ++j) refused.value[j] = at[j];
        return refused;
      }
    }
    at += c.width;
  }
  return check_stamp(stamp, last_stamp_ns, ahead_limit_ns);
}

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
