#include "model/attitude.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>

namespace quadcosim::model {

Eigen::Quaterniond quaternion_from_euler(const Euler& e) {
  const double cr = std::cos(0.5 * e.roll_rad), sr = std::sin(0.5 * e.roll_rad);
  const double cp = std::cos(0.5 * e.pitch_rad), sp = std::sin(0.5 * e.pitch_rad);
  const double cy = std::cos(0.5 * e.yaw_rad), sy = std::sin(0.5 * e.yaw_rad);
  // q = qz(yaw) * qy(pitch) * qx(roll), expanded.
  return Eigen::Quaterniond(cy * cp * cr + sy * sp * sr,   // w
                            cy * cp * sr - sy * sp * cr,   // x
                            cy * sp * cr + sy * cp * sr,   // y
                            sy * cp * cr - cy * sp * sr);  // z
}

Euler euler_from_quaternion(const Eigen::Quaterniond& q_in) {
  const double n = q_in.norm();
  if (!(n > 0.0) || !std::isfinite(n)) return {};
  const double w = q_in.w() / n, x = q_in.x() / n, y = q_in.y() / n, z = q_in.z() / n;
  Euler e;
  // sin(pitch) = -R(2,0) = 2 (w y - x z); cos(pitch) = |(R(0,0), R(1,0))|. atan2 of the two keeps full
  // precision near +-pi/2, where asin would lose half the digits.
  const double s = 2.0 * (w * y - x * z);
  const double c = std::hypot(1.0 - 2.0 * (y * y + z * z), 2.0 * (x * y + w * z));
  // Within ~sqrt(eps) of the lock roll and yaw are ill-conditioned (their atan2 arguments are all
  // ~cos(pitch)); treating it as the lock keeps the rebuilt rotation accurate to ~1e-8 everywhere.
  if (c < 1.5e-8) {  // gimbal lock: only yaw -+ roll is defined; report roll = 0
    e.pitch_rad = std::copysign(std::numbers::pi / 2.0, s);
    e.roll_rad = 0.0;
    e.yaw_rad = wrap_pi(-2.0 * std::copysign(1.0, s) * std::atan2(x, w));
    return e;
  }
  e.pitch_rad = std::atan2(s, c);
  e.roll_rad = std::atan2(2.0 * (w * x + y * z), 1.0 - 2.0 * (x * x + y * y));
  e.yaw_rad = std::atan2(2.0 * (w * z + x * y), 1.0 - 2.0 * (y * y + z * z));
  return e;
}

}  // namespace quadcosim::model
