#include "control/controller.hpp"

#include "model/quadrotor.hpp"

#include <algorithm>
#include <limits>

namespace quadcosim::control {

void rotor_speeds_output(const model::Quadrotor& model, const Reference& reference, const Eigen::Vector4d& omega_rad_s,
                         ControllerOutput& out) {
  out.omega_rad_s = omega_rad_s;
  const model::Wrench u = model.wrench(omega_rad_s);
  out.U = {u.thrust_N, u.torque_B_Nm.x(), u.torque_B_Nm.y(), u.torque_B_Nm.z()};
  out.roll_des_rad = reference.roll_rad;
  out.pitch_des_rad = reference.pitch_rad;
  out.yaw_des_rad = reference.yaw_rad;
  out.attitude_error = std::numeric_limits<double>::quiet_NaN();
  out.rotor_saturated = {};
  out.tilt_saturated = false;
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
