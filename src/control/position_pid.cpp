#include "control/position_pid.hpp"

#include <algorithm>
#include <cmath>

namespace quadcosim::control {

namespace {

struct Tilt {
  double roll, pitch;
};

Tilt tilt_for(const Eigen::Vector2d& a, double yaw, double g) {
  const double c = std::cos(yaw), s = std::sin(yaw);
  return {(a.x() * s - a.y() * c) / g, (a.x() * c + a.y() * s) / g};
}

}  // namespace

TiltSetpoint position_pid(const PositionGains& k, PositionPidState& st, const Eigen::Vector2d& p_des,
                          const Eigen::Vector2d& p, const Eigen::Vector2d& v, double yaw, double g, double dt_s) {
  const Eigen::Vector2d e = p_des - p;
  auto accel = [&](const Eigen::Vector2d& integral) -> Eigen::Vector2d {
    return k.kp * e + k.ki * integral - k.kd * v;
  };
  const Tilt unclamped = tilt_for(accel(st.integral_m_s), yaw, g);
  const bool saturated = std::abs(unclamped.roll) > k.max_tilt_rad || std::abs(unclamped.pitch) > k.max_tilt_rad;

  // Conditional integration: integrate an axis unless the output is saturated and the error would
  // push it further into saturation.
  for (int i = 0; i < 2; ++i) {
    const Eigen::Vector2d a = accel(st.integral_m_s);
    const bool winding = saturated && e[i] * a[i] > 0.0;
    if (!winding) {
      st.integral_m_s[i] = std::clamp(st.integral_m_s[i] + e[i] * dt_s, -k.integral_limit, k.integral_limit);
    }
  }

  const Tilt t = tilt_for(accel(st.integral_m_s), yaw, g);
  return {std::clamp(t.roll, -k.max_tilt_rad, k.max_tilt_rad), std::clamp(t.pitch, -k.max_tilt_rad, k.max_tilt_rad),
          saturated};
}

}  // namespace quadcosim::control
