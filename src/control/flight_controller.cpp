#include "control/flight_controller.hpp"

#include <Eigen/LU>
#include <cmath>

#include "model/attitude.hpp"
#include "model/mixer.hpp"

namespace quadcosim::control {

FlightController::FlightController(const ControllerParams& params) { set_params(params); }

void FlightController::set_params(const ControllerParams& params) {
  const auto& v = params.vehicle;
  // Design everything first, so a failing design leaves the controller unchanged.
  std::array<AxisLqr, 3> axes = {design_axis_lqr(v.Ixx_kg_m2, params.roll), design_axis_lqr(v.Iyy_kg_m2, params.pitch),
                                 design_axis_lqr(v.Izz_kg_m2, params.yaw)};
  mixer_inverse_ = model::mixer_matrix(v).inverse();
  axes_ = axes;
  params_ = params;
}

ControllerOutput FlightController::safety_command() const {
  ControllerOutput c;
  c.safety = true;
  const auto& v = params_.vehicle;
  const double w = params_.safety == SafetyMode::kHover ? v.hover_omega_rad_s() : v.motor.omega_min_rad_s;
  c.omega_rad_s.setConstant(w);
  return c;
}

namespace {
bool finite(const Observation& e) {
  return e.p_W.allFinite() && e.v_W.allFinite() && e.w_B.allFinite() && std::isfinite(e.roll_rad) &&
         std::isfinite(e.pitch_rad) && std::isfinite(e.yaw_rad);
}
}  // namespace

ControllerOutput FlightController::step(const Observation& obs, const Setpoint& sp, double dt_s) {
  // Algorithm 1, lines 3-5.
  if (!(obs.age_s <= params_.stale_limit_s) || !finite(obs)) return safety_command();

  const auto& v = params_.vehicle;
  ControllerOutput c;
  c.yaw_des_rad = sp.yaw_des_rad;
  if (sp.mode == Mode::kPosition) {
    const TiltSetpoint tilt = position_pid(params_.position, position_state_, sp.p_des_W.head<2>(), obs.p_W.head<2>(),
                                           obs.v_W.head<2>(), obs.yaw_rad, v.gravity_m_s2, dt_s);
    c.roll_des_rad = tilt.roll_rad;
    c.pitch_des_rad = tilt.pitch_rad;
    c.tilt_saturated = tilt.saturated;
  } else {
    c.roll_des_rad = sp.roll_des_rad;
    c.pitch_des_rad = sp.pitch_des_rad;
  }

  // Lines 7-11: attitude LQR on e = des - angle and the body rates.
  const double e_roll = c.roll_des_rad - obs.roll_rad;
  const double e_pitch = c.pitch_des_rad - obs.pitch_rad;
  const double e_yaw = model::wrap_pi(c.yaw_des_rad - obs.yaw_rad);
  c.U[1] = axes_[0].torque(e_roll, obs.w_B.x());
  c.U[2] = axes_[1].torque(e_pitch, obs.w_B.y());
  c.U[3] = axes_[2].torque(e_yaw, obs.w_B.z());

  // Lines 12-14: altitude PD, eq. (13).
  c.U[0] = collective_thrust(params_.altitude, v.mass_kg, v.gravity_m_s2, sp.p_des_W.z(), obs.p_W.z(), obs.v_W.z(),
                             obs.roll_rad, obs.pitch_rad);
  c.error << sp.p_des_W.z() - obs.p_W.z(), e_roll, e_pitch, e_yaw;

  // Lines 15-20.
  const Allocation a = allocate(mixer_inverse_, c.U, v.motor.omega_min_rad_s, v.motor.omega_max_rad_s);
  c.omega_rad_s = a.omega_rad_s;
  c.rotor_saturated = a.saturated;
  return c;
}

const char* to_string(Mode mode) { return mode == Mode::kAttitude ? "attitude" : "position"; }
const char* to_string(SafetyMode mode) { return mode == SafetyMode::kStop ? "stop" : "hover"; }

}  // namespace quadcosim::control
