// Horizontal position loop: PID on x, y (world) producing roll and pitch setpoints through yaw.
// Named in the paper's abstract; Algorithm 1 leaves it out.
#pragma once

#include <Eigen/Core>

namespace quadcosim::control {

struct PositionGains {
  // Defaults suit the paper's slow attitude loop (dominant pole near -0.74 1/s): the outer loop is
  // placed well below it (settles in about 25 s). With a faster attitude tuning, faster position gains
  // work: see scenarios/examples/position_step.yaml.
  double kp = 0.04;             ///< [1/s^2]: desired acceleration per metre of error
  double ki = 0.0;              ///< [1/s^3]: off by default (no steady disturbance in the nominal model)
  double kd = 0.35;             ///< [1/s]: per m/s of velocity
  double integral_limit = 2.0;  ///< [m s] bound on each axis's error integral
  double max_tilt_rad = 0.35;   ///< bound on the commanded roll and pitch [rad]
};

/// Integrator state of the position loop, one entry per world axis (x, y).
struct PositionPidState {
  Eigen::Vector2d integral_m_s = Eigen::Vector2d::Zero();
};

struct TiltSetpoint {
  double roll_rad = 0.0;
  double pitch_rad = 0.0;
  bool saturated = false;  ///< the tilt limit cut the command
};

/// a_des = kp e + ki int(e) - kd v (world x, y), then small-angle inversion of eq. (7) at heading yaw:
///   pitch = (a_x cos(yaw) + a_y sin(yaw)) / g,  roll = (a_x sin(yaw) - a_y cos(yaw)) / g,
/// each clamped to +-max_tilt. Anti-windup: the integral is bounded and does not grow while the
/// output is saturated in the direction of the error.
TiltSetpoint position_pid(const PositionGains& gains, PositionPidState& state, const Eigen::Vector2d& p_des_W,
                          const Eigen::Vector2d& p_W, const Eigen::Vector2d& v_W, double yaw_rad, double gravity_m_s2,
                          double dt_s);

}  // namespace quadcosim::control
