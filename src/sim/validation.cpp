#include "sim/validation.hpp"

#include <cmath>
#include <fmt/format.h>

namespace quadcosim::sim {

namespace {

// x - x is 0 for a finite x and NaN for an infinite or NaN one, and a NaN survives the sum: one test
// for the three values instead of a branch per value (these run on every sample).
bool finite(const msg::Vector3& v) { return (v.x - v.x) + (v.y - v.y) + (v.z - v.z) == 0.0; }
bool finite(const msg::Quaternion& q) { return (q.x - q.x) + (q.y - q.y) + (q.z - q.z) + (q.w - q.w) == 0.0; }

// | |q| - 1 | <= tolerance, tested on |q|^2 (no square root on every sample); false for NaN.
constexpr double kMinNormSquared = (1.0 - kQuaternionNormTolerance) * (1.0 - kQuaternionNormTolerance);
constexpr double kMaxNormSquared = (1.0 + kQuaternionNormTolerance) * (1.0 + kQuaternionNormTolerance);
double norm_squared(const msg::Quaternion& q) { return q.x * q.x + q.y * q.y + q.z * q.z + q.w * q.w; }
bool unit_norm(double n2) { return n2 >= kMinNormSquared && n2 <= kMaxNormSquared; }
std::string shown(const msg::Vector3& v) { return fmt::format("({:g}, {:g}, {:g})", v.x, v.y, v.z); }
std::string shown(const msg::Quaternion& q) {
  return fmt::format("(x {:g}, y {:g}, z {:g}, w {:g})", q.x, q.y, q.z, q.w);
}

SensorCheck fault(SensorFault f, std::string reason) { return {f, std::move(reason)}; }

SensorCheck check_stamp(const msg::Time& t, std::int64_t last_stamp_ns) {
  if (t.sec < 0 || t.nanosec >= 1'000'000'000u) {
    return fault(SensorFault::kBadStamp,
                 fmt::format("stamp sec {} nanosec {}: expected sec >= 0 and nanosec < 1e9", t.sec, t.nanosec));
  }
  if (t.to_ns() < last_stamp_ns) {
    return fault(SensorFault::kStampBackwards,
                 fmt::format("stamp {} ns is older than the newest accepted, {} ns", t.to_ns(), last_stamp_ns));
  }
  return {};
}

SensorCheck check_vector(const char* field, const msg::Vector3& v) {
  if (finite(v)) return {};
  return fault(SensorFault::kNonFinite, std::string(field) + " " + shown(v) + ": expected finite values");
}

SensorCheck check_orientation(const msg::Quaternion& q) {
  if (!finite(q)) return fault(SensorFault::kNonFinite, "orientation " + shown(q) + ": expected finite values");
  const double n2 = norm_squared(q);
  if (!unit_norm(n2)) {
    return fault(SensorFault::kBadQuaternion,
                 fmt::format("orientation {} has norm {:g}: expected a unit quaternion (within {:g})", shown(q),
                             std::sqrt(n2), kQuaternionNormTolerance));
  }
  return {};
}

// The same acceptance tests as the check_* functions, as plain booleans: every sample is checked, so
// the common case (all fine) builds no SensorCheck per field; only a refused sample goes through the
// check_* functions, which say why.
bool stamp_ok(const msg::Time& t, std::int64_t last_stamp_ns) {
  return t.sec >= 0 && t.nanosec < 1'000'000'000u && t.to_ns() >= last_stamp_ns;
}
bool orientation_ok(const msg::Quaternion& q) { return unit_norm(norm_squared(q)); }  // NaN, Inf: false

// The first fault among the checks, in order.
template <class... Checks>
SensorCheck first_fault(Checks&&... checks) {
  SensorCheck out;
  ((out.ok() ? (out = checks(), 0) : 0), ...);
  return out;
}

}  // namespace

bool command_ok(const msg::Float64MultiArray& m, double omega_max_rad_s) {
  if (m.data.size() != 4) return false;
  bool ok = true;
  for (int i = 0; i < 4; ++i) ok &= m.data[i] >= 0.0 && m.data[i] <= omega_max_rad_s;  // NaN: false
  return ok;
}

CommandCheck validate_command(const msg::Float64MultiArray& m, double omega_max_rad_s) {
  CommandCheck out;
  if (m.data.size() != 4) {
    out.reason = fmt::format("{} values, expected 4 rotor speeds", m.data.size());
    return out;
  }
  for (int i = 0; i < 4; ++i) {
    if (!std::isfinite(m.data[i])) {
      out.reason = fmt::format("rotor {} speed is {}, expected a finite number", i + 1, m.data[i]);
      return out;
    }
  }
  out.verdict = CommandVerdict::kAccepted;
  for (int i = 0; i < 4; ++i) {
    const double w = m.data[i];
    double c = w;
    if (w < 0.0) c = 0.0;
    if (w > omega_max_rad_s) c = omega_max_rad_s;
    if (c != w && out.verdict == CommandVerdict::kAccepted) {
      out.verdict = CommandVerdict::kClamped;
      out.reason = fmt::format("rotor {} speed {:g} rad/s clamped to {:g} (range [0, {:g}])", i + 1, w, c,
                               omega_max_rad_s);
    }
    out.omega_rad_s[i] = c;
  }
  return out;
}

const char* to_string(SensorFault f) {
  switch (f) {
    case SensorFault::kNone: return "accepted";
    case SensorFault::kNonFinite: return "non-finite value";
    case SensorFault::kBadQuaternion: return "non-unit quaternion";
    case SensorFault::kBadStamp: return "malformed stamp";
    case SensorFault::kStampBackwards: return "stamp went backwards";
  }
  return "?";
}

bool pose_ok(const msg::PoseStamped& m, std::int64_t last_stamp_ns) {
  return finite(m.position) && orientation_ok(m.orientation) && stamp_ok(m.header.stamp, last_stamp_ns);
}

bool velocity_ok(const msg::TwistStamped& m, std::int64_t last_stamp_ns) {
  return finite(m.linear) && finite(m.angular) && stamp_ok(m.header.stamp, last_stamp_ns);
}

bool imu_ok(const msg::Imu& m, std::int64_t last_stamp_ns) {
  return orientation_ok(m.orientation) && finite(m.angular_velocity) && finite(m.linear_acceleration) &&
         stamp_ok(m.header.stamp, last_stamp_ns);
}

SensorCheck validate_pose(const msg::PoseStamped& m, std::int64_t last_stamp_ns) {
  if (pose_ok(m, last_stamp_ns)) return {};
  return first_fault([&] { return check_vector("position", m.position); },
                     [&] { return check_orientation(m.orientation); },
                     [&] { return check_stamp(m.header.stamp, last_stamp_ns); });
}

SensorCheck validate_velocity(const msg::TwistStamped& m, std::int64_t last_stamp_ns) {
  if (velocity_ok(m, last_stamp_ns)) return {};
  return first_fault([&] { return check_vector("linear", m.linear); },
                     [&] { return check_vector("angular", m.angular); },
                     [&] { return check_stamp(m.header.stamp, last_stamp_ns); });
}

SensorCheck validate_imu(const msg::Imu& m, std::int64_t last_stamp_ns) {
  if (imu_ok(m, last_stamp_ns)) return {};
  return first_fault([&] { return check_orientation(m.orientation); },
                     [&] { return check_vector("angular_velocity", m.angular_velocity); },
                     [&] { return check_vector("linear_acceleration", m.linear_acceleration); },
                     [&] { return check_stamp(m.header.stamp, last_stamp_ns); });
}

}  // namespace quadcosim::sim
