#include "control/controller.hpp"

#include <algorithm>

namespace quadcosim::control {

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
