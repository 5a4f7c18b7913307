#include "controllers/paper/paper_controller.hpp"

#include <Eigen/LU>
#include <cmath>

#include "model/attitude.hpp"
#include "model/mixer.hpp"

namespace quadcosim::controllers {

namespace {
constexpr double kBig = 1e9;
using Table = control::ParameterTable<PaperParams>;

Table make_table() {
  return Table({
      Table::number(
          "altitude.kp", "N/m", 0, kBig, "altitude P gain K_p,z, eq. (12)",
          [](auto& p) -> auto& { return p.altitude.kp; }),
      Table::number(
          "altitude.kd", "N s/m", 0, kBig, "altitude D gain K_d,z, eq. (12)",
          [](auto& p) -> auto& { return p.altitude.kd; }),
      Table::number(
          "altitude.min_cos_tilt", "", 0.05, 1, "floor on cos(roll) cos(pitch) in eq. (13)",
          [](auto& p) -> auto& { return p.altitude.min_cos_tilt; }),
      Table::number(
          "lqr.roll.q_angle", "1/rad^2", 1e-12, kBig, "roll LQR weight on angle error",
          [](auto& p) -> auto& { return p.roll.q_angle; }),
      Table::number(
          "lqr.roll.q_rate", "s^2/rad^2", 0, kBig, "roll LQR weight on rate",
          [](auto& p) -> auto& { return p.roll.q_rate; }),
      Table::number(
          "lqr.roll.r", "1/(N m)^2", 1e-12, kBig, "roll LQR weight on torque",
          [](auto& p) -> auto& { return p.roll.r; }),
      Table::number(
          "lqr.pitch.q_angle", "1/rad^2", 1e-12, kBig, "pitch LQR weight on angle error",
          [](auto& p) -> auto& { return p.pitch.q_angle; }),
      Table::number(
          "lqr.pitch.q_rate", "s^2/rad^2", 0, kBig, "pitch LQR weight on rate",
          [](auto& p) -> auto& { return p.pitch.q_rate; }),
      Table::number(
          "lqr.pitch.r", "1/(N m)^2", 1e-12, kBig, "pitch LQR weight on torque",
          [](auto& p) -> auto& { return p.pitch.r; }),
      Table::number(
          "lqr.yaw.q_angle", "1/rad^2", 1e-12, kBig, "yaw LQR weight on angle error",
          [](auto& p) -> auto& { return p.yaw.q_angle; }),
      Table::number(
          "lqr.yaw.q_rate", "s^2/rad^2", 0, kBig, "yaw LQR weight on rate",
          [](auto& p) -> auto& { return p.yaw.q_rate; }),
      Table::number(
          "lqr.yaw.r", "1/(N m)^2", 1e-12, kBig, "yaw LQR weight on torque", [](auto& p) -> auto& { return p.yaw.r; }),
      Table::number(
          "position.kp", "1/s^2", 0, kBig, "position P gain", [](auto& p) -> auto& { return p.position.kp; }),
      Table::number(
          "position.ki", "1/s^3", 0, kBig, "position I gain", [](auto& p) -> auto& { return p.position.ki; }),
      Table::number(
          "position.kd", "1/s", 0, kBig, "position D gain (on velocity)",
          [](auto& p) -> auto& { return p.position.kd; }),
      Table::number(
          "position.integral_limit", "m s", 0, kBig, "anti-windup bound on each axis's error integral",
          [](auto& p) -> auto& { return p.position.integral_limit; }),
      Table::number(
          "position.max_tilt", "rad", 0.01, 1.2, "tilt limit on the roll/pitch the position loop commands",
          [](auto& p) -> auto& { return p.position.max_tilt_rad; }),
  });
}

const std::array<std::string, 4> kOutputNames = {"error.z", "error.roll", "error.pitch", "error.yaw"};
}  // namespace

PaperController::PaperController(const model::VehicleParams& vehicle, const PaperParams& params)
    : ControllerWith(params), vehicle_(vehicle) {
  configure(params);
}

const control::ParameterTable<PaperParams>& PaperController::table() const {
  static const Table table = make_table();
  return table;
}

std::span<const std::string> PaperController::output_names() const { return kOutputNames; }

void PaperController::configure(const PaperParams& next) {
  const auto& v = vehicle_;
  // Design everything first, so a failing design leaves the controller unchanged.
  std::array<control::AxisLqr, 3> axes = {control::design_axis_lqr(v.Ixx_kg_m2, next.roll),
                                          control::design_axis_lqr(v.Iyy_kg_m2, next.pitch),
                                          control::design_axis_lqr(v.Izz_kg_m2, next.yaw)};
  allocation_ = control::RotorAllocation(v);
  axes_ = axes;
}

void PaperController::step(const control::Observation& obs, const control::Reference& ref, double dt_s,
                           control::ControllerOutput& c) {
  const auto& v = vehicle_;
  const PaperParams& params = this->params();
  c.yaw_des_rad = ref.yaw_rad;
  c.tilt_saturated = false;
  if (ref.mode == control::Mode::kPosition) {
    const control::TiltSetpoint tilt =
        control::position_pid(params.position, position_state_, ref.p_W.head<2>(), obs.p_W.head<2>(), obs.v_W.head<2>(),
                              obs.yaw_rad, v.gravity_m_s2, dt_s);
    c.roll_des_rad = tilt.roll_rad;
    c.pitch_des_rad = tilt.pitch_rad;
    c.tilt_saturated = tilt.saturated;
  } else {
    c.roll_des_rad = ref.roll_rad;
    c.pitch_des_rad = ref.pitch_rad;
  }

  // Lines 7-11: attitude LQR on e = des - angle and the body rates.
  const double e_roll = c.roll_des_rad - obs.roll_rad;
  const double e_pitch = c.pitch_des_rad - obs.pitch_rad;
  const double e_yaw = model::wrap_pi(c.yaw_des_rad - obs.yaw_rad);
  c.U[1] = axes_[0].torque(e_roll, obs.w_B.x());
  c.U[2] = axes_[1].torque(e_pitch, obs.w_B.y());
  c.U[3] = axes_[2].torque(e_yaw, obs.w_B.z());

  // Lines 12-14: altitude PD, eq. (13).
  c.U[0] = control::collective_thrust(params.altitude, v.mass_kg, v.gravity_m_s2, ref.p_W.z(), obs.p_W.z(), obs.v_W.z(),
                                      obs.roll_rad, obs.pitch_rad);
  c.outputs[0] = ref.p_W.z() - obs.p_W.z();
  c.outputs[1] = e_roll;
  c.outputs[2] = e_pitch;
  c.outputs[3] = e_yaw;
  c.attitude_error =
      control::attitude_error(model::quaternion_from_euler({c.roll_des_rad, c.pitch_des_rad, c.yaw_des_rad}), obs.q_WB);

  // Lines 15-20.
  const control::Allocation a = allocation_.allocate(c.U, v.motor.omega_min_rad_s, v.motor.omega_max_rad_s);
  model::assign_rotors(c.omega_rad_s, a.omega_rad_s);
  c.rotor_saturated = a.saturated;
}

const PaperController* paper_controller(const control::ControllerConfig& config) {
  return dynamic_cast<const PaperController*>(config.controller.get());
}

}  // namespace quadcosim::controllers
