#include "sim/validation.hpp"

#include <fmt/format.h>
#include <algorithm>
#include <cmath>
#include <optional>

namespace quadcosim::sim {

// ---------------------------------------------------------------------------------------------
// Motor commands

namespace {

// The acceptance rule for one speed [rad/s]: in the motor range [0, omega_max] (-0 included); false
// for NaN and Inf.
bool in_range(double w, double omega_max_rad_s) { return w >= 0.0 && w <= omega_max_rad_s; }

// A command with a speed out of range: the first non-finite speed rejects it; otherwise the speeds out
// of range are clamped to the nearer end and the first of them is named. Out of line: the common
// case (all four in range) never comes here.
[[gnu::noinline, gnu::cold]] void find_command_fault(const double* w, CommandCheck& out) {
  const int n = out.rotors;
  for (int i = 0; i < n; ++i) {
    if (!std::isfinite(w[i])) {
      out.fault = CommandFault::kNonFinite;
      out.rotor = i;
      out.value = w[i];
      out.omega_rad_s.setZero();
      return;
    }
  }
  for (int i = n - 1; i >= 0; --i) {  // downwards, so that the first rotor out of range is the one named
    if (in_range(w[i], out.omega_max_rad_s)) continue;
    out.omega_rad_s[i] = w[i] > out.omega_max_rad_s ? out.omega_max_rad_s : 0.0;
    out.fault = CommandFault::kOutOfRange;
    out.rotor = i;
    out.value = w[i];
  }
}

// A command at a level above rotor speeds (out of line: rotor speeds are the common case).
[[gnu::noinline]] void check_level_values(control::CommandLevel level, const double* values, std::size_t count,
                                          CommandCheck& out) {
  out.level = level;
  if (level == control::CommandLevel::kRotorThrusts && out.rotors != 4) {
    out.fault = CommandFault::kLevelNotForVehicle;
    out.omega_rad_s.setZero(4);
    return;
  }
  if (count != 4) {
    out.fault = CommandFault::kWrongLength;
    out.values = count;
    out.omega_rad_s.setZero(4);
    return;
  }
  out.omega_rad_s.resize(4);
  for (int i = 0; i < 4; ++i) {
    const double v = values[i];
    out.omega_rad_s[i] = v;
    if (!std::isfinite(v)) {
      out.fault = CommandFault::kNonFinite;
      out.rotor = i;
      out.value = v;
      out.omega_rad_s.setZero();
      return;
    }
  }
  if (out.level != control::CommandLevel::kRotorThrusts) return;
  for (int i = 3; i >= 0; --i) {  // downwards, so that the first rotor out of range is the one named
    if (out.omega_rad_s[i] >= 0.0) continue;
    out.fault = CommandFault::kOutOfRange;
    out.rotor = i;
    out.value = out.omega_rad_s[i];
    out.omega_rad_s[i] = 0.0;
  }
}

// Exactly out.rotors rotor speeds, each in [0, omega_max] (clamped) and finite (else rejected).
void check_rotor_speeds(const double* w, std::size_t count, CommandCheck& out) {
  const int n = out.rotors;
  if (count != static_cast<std::size_t>(n)) {
    out.fault = CommandFault::kWrongLength;
    out.values = count;
    out.omega_rad_s.setZero(n);
    return;
  }
  bool ok = true;
  if (n == 4) {  // the quadrotor's command, unrolled
    out.omega_rad_s = model::Vector4(w[0], w[1], w[2], w[3]);
    for (int i = 0; i < 4; ++i) ok &= in_range(w[i], out.omega_max_rad_s);  // no branch per speed
  } else {
    out.omega_rad_s = Eigen::Map<const model::RotorVector>(w, n);
    for (int i = 0; i < n; ++i) ok &= in_range(w[i], out.omega_max_rad_s);
  }
  if (!ok) find_command_fault(w, out);
}

}  // namespace

CommandCheck check_command(const msg::Float64MultiArray& m, double omega_max_rad_s, int rotor_count) {
  CommandCheck out;
  out.omega_max_rad_s = omega_max_rad_s;
  out.rotors = rotor_count;
  if (!m.dim.empty()) {
    if (const std::string_view name = msg::command_level_name(m); !name.empty()) {
      const std::optional<control::CommandLevel> level = control::command_level_from_string(name);
      if (!level) {
        out.fault = CommandFault::kUnknownLevel;
        out.omega_rad_s.setZero(4);
        const std::size_t n = std::min(name.size(), out.unknown_level.size() - 1);
        std::copy_n(name.data(), n, out.unknown_level.data());
        return out;
      }
      // "level=rotor_speeds" is rotor speeds, as no level dimension is.
      if (*level != control::CommandLevel::kRotorSpeeds) {
        check_level_values(*level, m.data.data(), m.data.size(), out);
        return out;
      }
    }
  }
  check_rotor_speeds(m.data.data(), m.data.size(), out);
  return out;
}

CommandCheck check_command(control::CommandLevel level, const double* values, std::size_t count, double omega_max_rad_s,
                           int rotor_count, double attitude_norm) {
  CommandCheck out;
  out.omega_max_rad_s = omega_max_rad_s;
  out.rotors = rotor_count;
  if (level == control::CommandLevel::kRotorSpeeds) {
    check_rotor_speeds(values, count, out);
    return out;
  }
  check_level_values(level, values, count, out);
  if (out.verdict() != CommandVerdict::kRejected && !(std::abs(attitude_norm - 1.0) <= kQuaternionNormTolerance)) {
    out.fault = CommandFault::kBadQuaternion;
    out.quaternion_norm = attitude_norm;
    out.omega_rad_s.setZero();
  }
  return out;
}

CommandVerdict CommandCheck::verdict() const {
  switch (fault) {
    case CommandFault::kNone: return CommandVerdict::kAccepted;
    case CommandFault::kOutOfRange: return CommandVerdict::kClamped;
    case CommandFault::kWrongLength:
    case CommandFault::kNonFinite:
    case CommandFault::kUnknownLevel:
    case CommandFault::kBadQuaternion:
    case CommandFault::kLevelNotForVehicle: break;
  }
  return CommandVerdict::kRejected;
}

std::string CommandCheck::reason() const {
  if (fault == CommandFault::kUnknownLevel) return control::unknown_command_level(unknown_level.data());
  if (level != control::CommandLevel::kRotorSpeeds) {
    const std::string_view name = control::to_string(level);
    switch (fault) {
      case CommandFault::kNone: return "";
      case CommandFault::kWrongLength: return fmt::format("{} values, expected 4 for level {}", values, name);
      case CommandFault::kNonFinite:
        return fmt::format("{} value {} ({}) is {}, expected a finite number", name, rotor + 1,
                           control::setpoint_fields(level)[static_cast<std::size_t>(rotor)], value);
      case CommandFault::kOutOfRange: return fmt::format("rotor {} thrust {:g} N clamped to 0", rotor + 1, value);
      case CommandFault::kBadQuaternion:
        return fmt::format("{} attitude has norm {:g}, expected a unit quaternion (x, y, z, w)", name, quaternion_norm);
      case CommandFault::kLevelNotForVehicle:
        return fmt::format(
            "level {} takes one thrust per rotor of a four-rotor vehicle; this vehicle has {} rotors "
            "(command it at rotor_speeds or a level above)",
            name, rotors);
      case CommandFault::kUnknownLevel: break;
    }
    return "?";
  }
  switch (fault) {
    case CommandFault::kNone: return "";
    case CommandFault::kUnknownLevel:
    case CommandFault::kBadQuaternion:
    case CommandFault::kLevelNotForVehicle: return "?";
    case CommandFault::kWrongLength: return fmt::format("{} values, expected {} rotor speeds", values, rotors);
    case CommandFault::kNonFinite:
      return fmt::format("rotor {} speed is {}, expected a finite number", rotor + 1, value);
    case CommandFault::kOutOfRange:
      return fmt::format("rotor {} speed {:g} rad/s clamped to {:g} (range [0, {:g}])", rotor + 1, value,
                         omega_rad_s[rotor], omega_max_rad_s);
  }
  return "?";
}

// ---------------------------------------------------------------------------------------------
// Sensor messages

namespace {

// x - x is 0 for a finite x and NaN for an infinite or NaN one, and a NaN survives the sum: one test
// for the three values instead of a branch per value (these run on every sample).
bool finite(const msg::Vector3& v) { return (v.x - v.x) + (v.y - v.y) + (v.z - v.z) == 0.0; }
bool finite(const msg::Quaternion& q) { return (q.x - q.x) + (q.y - q.y) + (q.z - q.z) + (q.w - q.w) == 0.0; }

// | |q| - 1 | <= tolerance, tested on |q|^2 (no square root on every sample); false for NaN and Inf.
constexpr double kMinNormSquared = (1.0 - kQuaternionNormTolerance) * (1.0 - kQuaternionNormTolerance);
constexpr double kMaxNormSquared = (1.0 + kQuaternionNormTolerance) * (1.0 + kQuaternionNormTolerance);
double norm_squared(double x, double y, double z, double w) { return x * x + y * y + z * z + w * w; }

// Each rule below is stated once: true when the field passes; otherwise the fault is written into
// `c` (out of line: the common case never comes there) and false returned, so that `&&` over a
// message's rules stops at the first fault.
[[gnu::noinline, gnu::cold]] bool refuse_vector(SensorCheck& c, SensorField field, const msg::Vector3& v) {
  c.fault = SensorFault::kNonFinite;
  c.field = field;
  c.value = {v.x, v.y, v.z, 0.0};
  return false;
}

bool vector_ok(SensorCheck& c, SensorField field, const msg::Vector3& v) {
  return finite(v) || refuse_vector(c, field, v);
}

// A refused orientation is named non-finite before non-unit.
[[gnu::noinline, gnu::cold]] bool refuse_orientation(SensorCheck& c, const msg::Quaternion& q) {
  c.fault = finite(q) ? SensorFault::kBadQuaternion : SensorFault::kNonFinite;
  c.field = SensorField::kOrientation;
  c.value = {q.x, q.y, q.z, q.w};
  return false;
}

// A unit norm implies finite values (a NaN or Inf makes |q|^2 NaN or Inf), so the norm is the one
// test on the common path.
bool orientation_ok(SensorCheck& c, const msg::Quaternion& q) {
  const double n2 = norm_squared(q.x, q.y, q.z, q.w);
  return (n2 >= kMinNormSquared && n2 <= kMaxNormSquared) || refuse_orientation(c, q);
}

[[gnu::noinline, gnu::cold]] bool refuse_stamp(SensorCheck& c, SensorFault f, const msg::Time& t,
                                               std::int64_t newest_ns, std::int64_t ahead_limit_ns = 0) {
  c.fault = f;
  c.field = SensorField::kStamp;
  c.stamp = t;
  c.newest_ns = newest_ns;
  c.ahead_limit_ns = ahead_limit_ns;
  return false;
}

bool stamp_ok(SensorCheck& c, const msg::Time& t, std::int64_t last_stamp_ns, std::int64_t ahead_limit_ns) {
  if (t.sec < 0 || t.nanosec >= 1'000'000'000u) return refuse_stamp(c, SensorFault::kBadStamp, t, 0);
  const std::int64_t ns = t.to_ns();
  if (ns < last_stamp_ns) return refuse_stamp(c, SensorFault::kStampBackwards, t, last_stamp_ns);
  // Before the first (INT64_MIN) any stamp is accepted; the difference is taken only after one.
  return last_stamp_ns == INT64_MIN || ns - last_stamp_ns <= ahead_limit_ns ||
         refuse_stamp(c, SensorFault::kStampAhead, t, last_stamp_ns, ahead_limit_ns);
}

std::string shown(const std::array<double, 4>& v, bool quaternion) {
  if (quaternion) return fmt::format("(x {:g}, y {:g}, z {:g}, w {:g})", v[0], v[1], v[2], v[3]);
  return fmt::format("({:g}, {:g}, {:g})", v[0], v[1], v[2]);
}

}  // namespace

SensorCheck check_pose(const msg::PoseStamped& m, std::int64_t last_stamp_ns, std::int64_t ahead_limit_ns) {
  SensorCheck c;
  (void)(vector_ok(c, SensorField::kPosition, m.position) && orientation_ok(c, m.orientation) &&
         stamp_ok(c, m.header.stamp, last_stamp_ns, ahead_limit_ns));
  return c;
}

SensorCheck check_velocity(const msg::TwistStamped& m, std::int64_t last_stamp_ns, std::int64_t ahead_limit_ns) {
  SensorCheck c;
  (void)(vector_ok(c, SensorField::kLinear, m.linear) && vector_ok(c, SensorField::kAngular, m.angular) &&
         stamp_ok(c, m.header.stamp, last_stamp_ns, ahead_limit_ns));
  return c;
}

SensorCheck check_imu(const msg::Imu& m, std::int64_t last_stamp_ns, std::int64_t ahead_limit_ns) {
  SensorCheck c;
  (void)(orientation_ok(c, m.orientation) && vector_ok(c, SensorField::kAngularVelocity, m.angular_velocity) &&
         vector_ok(c, SensorField::kLinearAcceleration, m.linear_acceleration) &&
         stamp_ok(c, m.header.stamp, last_stamp_ns, ahead_limit_ns));
  return c;
}

SensorCheck check_stamp(const msg::Time& stamp, std::int64_t last_stamp_ns, std::int64_t ahead_limit_ns) {
  SensorCheck c;
  (void)stamp_ok(c, stamp, last_stamp_ns, ahead_limit_ns);
  return c;
}

const char* to_string(SensorFault f) {
  switch (f) {
    case SensorFault::kNone: return "accepted";
    case SensorFault::kNonFinite: return "non-finite value";
    case SensorFault::kBadQuaternion: return "non-unit quaternion";
    case SensorFault::kBadStamp: return "malformed stamp";
    case SensorFault::kStampBackwards: return "stamp went backwards";
    case SensorFault::kStampAhead: return "stamp too far ahead";
  }
  return "?";
}

const char* to_string(SensorField f) {
  switch (f) {
    case SensorField::kNone: return "";
    case SensorField::kStamp: return "stamp";
    case SensorField::kPosition: return "position";
    case SensorField::kOrientation: return "orientation";
    case SensorField::kLinear: return "linear";
    case SensorField::kAngular: return "angular";
    case SensorField::kAngularVelocity: return "angular_velocity";
    case SensorField::kLinearAcceleration: return "linear_acceleration";
    case SensorField::kSample: return "sample";
  }
  return "?";
}

std::string SensorCheck::reason() const {
  const bool quaternion = field == SensorField::kOrientation;
  switch (fault) {
    case SensorFault::kNone: return "";
    case SensorFault::kNonFinite:
      if (field == SensorField::kSample) {
        return fmt::format("{} {} {}: expected finite values", sensor, column,
                           width == 1 ? fmt::format("{:g}", value[0]) : shown(value, false));
      }
      return fmt::format("{} {}: expected finite values", to_string(field), shown(value, quaternion));
    case SensorFault::kBadQuaternion:
      return fmt::format("orientation {} has norm {:g}: expected a unit quaternion (within {:g})", shown(value, true),
                         std::sqrt(norm_squared(value[0], value[1], value[2], value[3])), kQuaternionNormTolerance);
    case SensorFault::kBadStamp:
      return fmt::format("stamp sec {} nanosec {}: expected sec >= 0 and nanosec < 1e9", stamp.sec, stamp.nanosec);
    case SensorFault::kStampBackwards:
      return fmt::format("stamp {} ns is older than the newest accepted, {} ns", stamp.to_ns(), newest_ns);
    case SensorFault::kStampAhead:
      return fmt::format("stamp {} ns is {:g} s ahead of the newest accepted, {} ns (at most {:g} s)", stamp.to_ns(),
                         static_cast<double>(stamp.to_ns() - newest_ns) / 1e9, newest_ns,
                         static_cast<double>(ahead_limit_ns) / 1e9);
  }
  return "?";
}

}  // namespace quadcosim::sim
