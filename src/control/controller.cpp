#include "control/controller.hpp"

#include "model/quadrotor.hpp"

#include <algorithm>
#include <limits>

namespace quadcosim::control {

ReportedOutputs ReportedOutputs::find(std::span<const std::string> output_names) {
  ReportedOutputs r;
  for (std::size_t i = 0; i < output_names.size(); ++i) {
    const std::string& name = output_names[i];
    int* place = name == kRollDes         ? &r.roll_des
                 : name == kPitchDes      ? &r.pitch_des
                 : name == kYawDes        ? &r.yaw_des
                 : name == kTiltSaturated ? &r.tilt_saturated
                                          : nullptr;
    if (place) *place = static_cast<int>(i);
  }
  return r;
}

void rotor_speeds_output(const model::Quadrotor& model, const Reference& reference,
                         const model::RotorVector& omega_rad_s, const ReportedOutputs& reported,
                         ControllerOutput& out) {
  out.omega_rad_s = omega_rad_s;
  const model::Wrench u = model.wrench(omega_rad_s);
  out.U = {u.thrust_N, u.torque_B_Nm.x(), u.torque_B_Nm.y(), u.torque_B_Nm.z()};
  const bool attitude_mode = reference.mode == Mode::kAttitude;
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const auto figure = [&](int place, double otherwise) {
    return place >= 0 && static_cast<std::size_t>(place) < out.outputs.size() ? out.outputs[place] : otherwise;
  };
  out.roll_des_rad = figure(reported.roll_des, attitude_mode ? reference.roll_rad : nan);
  out.pitch_des_rad = figure(reported.pitch_des, attitude_mode ? reference.pitch_rad : nan);
  out.yaw_des_rad = figure(reported.yaw_des, reference.yaw_rad);
  out.attitude_error = nan;
  const model::MotorParams& motor = model.params().motor;
  out.rotor_saturated.reset(static_cast<int>(omega_rad_s.size()));
  for (int i = 0; i < static_cast<int>(omega_rad_s.size()); ++i)
    out.rotor_saturated[i] = omega_rad_s[i] >= motor.omega_max_rad_s || omega_rad_s[i] <= motor.omega_min_rad_s;
  out.tilt_saturated = figure(reported.tilt_saturated, 0.0) != 0.0;
}

double attitude_error(const Eigen::Quaterniond& q_des, const Eigen::Quaterniond& q) {
  // 1/2 tr(I - R_d^T R) = 1 - cos(theta) for the rotation R_d^T R by theta; with the unit quaternion
  // d = q_des^* q, cos(theta) = 2 d_w^2 - 1, so Psi = 2 (1 - d_w^2) = 2 |d_vec|^2 / |d|^2.
  const Eigen::Quaterniond d = q_des.conjugate() * q;
  const double n2 = d.squaredNorm();
  if (!(n2 > 0.0)) return 0.0;
  return std::clamp(2.0 * d.vec().squaredNorm() / n2, 0.0, 2.0);
}

const char* to_string(Mode mode) { return mode == Mode::kAttitude ? "attitude" : "position"; }

}  // namespace quadcosim::control
