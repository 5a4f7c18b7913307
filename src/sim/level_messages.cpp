#include "sim/level_messages.hpp"

#include <Eigen/Geometry>
#include <cmath>
#include <limits>

#include "model/attitude.hpp"

namespace quadcosim::msg {

namespace {
LevelValues of_array(control::CommandLevel level, const std::vector<double>& values) {
  LevelValues v;
  v.level = level;
  v.rotors = &values;
  return v;
}
LevelValues of_four(control::CommandLevel level, double a, double b, double c, double d) {
  LevelValues v;
  v.level = level;
  v.four = {a, b, c, d};
  return v;
}
}  // namespace

LevelValues level_values(const RotorSpeeds& m) { return of_array(RotorSpeeds::kLevel, m.omega_rad_s); }
LevelValues level_values(const RotorThrusts& m) { return of_array(RotorThrusts::kLevel, m.thrust_n); }
LevelValues level_values(const ThrustRates& m) {
  const Vector3& w = m.body_rates_rad_s;
  return of_four(ThrustRates::kLevel, m.thrust_n, w.x, w.y, w.z);
}
LevelValues level_values(const ThrustAttitude& m) {
  const Quaternion& q = m.attitude;
  const Eigen::Quaterniond q_WB(q.w, q.x, q.y, q.z);
  const double norm = q_WB.norm();
  // A non-finite component reaches the check as a non-finite roll, pitch and yaw (euler_from_quaternion
  // gives zeros for it), so that it is named like any other.
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const model::Euler e = std::isfinite(norm) ? model::euler_from_quaternion(q_WB) : model::Euler{nan, nan, nan};
  LevelValues v = of_four(ThrustAttitude::kLevel, m.thrust_n, e.roll_rad, e.pitch_rad, e.yaw_rad);
  v.attitude_norm = norm;
  return v;
}
LevelValues level_values(const ThrustTorque& m) {
  const Vector3& u = m.torque_nm;
  return of_four(ThrustTorque::kLevel, m.thrust_n, u.x, u.y, u.z);
}
LevelValues level_values(const VelocityYaw& m) {
  const Vector3& v = m.velocity_m_s;
  return of_four(VelocityYaw::kLevel, v.x, v.y, v.z, m.yaw_rad);
}
LevelValues level_values(const AccelerationYaw& m) {
  const Vector3& a = m.acceleration_m_s2;
  return of_four(AccelerationYaw::kLevel, a.x, a.y, a.z, m.yaw_rad);
}

}  // namespace quadcosim::msg
