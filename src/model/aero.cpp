#include "model/aero.hpp"

#include <algorithm>
#include <cmath>
#include <string>

namespace quadcosim::model {

bool AeroParams::active() const {
  return !linear_drag_N_s_m.isZero(0.0) || !quadratic_drag_N_s2_m2.isZero(0.0) || rotor_drag_N_s_m_per_rad_s != 0.0 ||
         ground_effect_rotor_radius_m != 0.0;
}

Eigen::Vector3d aero_force_W(const AeroParams& a, const Eigen::Matrix3d& R_WB, const Eigen::Vector3d& v_W,
                             const Eigen::Vector3d& wind_W, const Eigen::Vector4d& omega_rad_s) {
  const Eigen::Vector3d v_rB = R_WB.transpose() * (v_W - wind_W);
  Eigen::Vector3d F_B = -a.linear_drag_N_s_m.cwiseProduct(v_rB) -
                        a.quadratic_drag_N_s2_m2.cwiseProduct(v_rB.cwiseAbs()).cwiseProduct(v_rB);
  if (a.rotor_drag_N_s_m_per_rad_s != 0.0) {
    const double k = a.rotor_drag_N_s_m_per_rad_s * omega_rad_s.cwiseAbs().sum();
    F_B.x() -= k * v_rB.x();
    F_B.y() -= k * v_rB.y();
  }
  return R_WB * F_B;
}

double ground_effect_factor(const AeroParams& a, double z_m) {
  const double R = a.ground_effect_rotor_radius_m;
  if (R <= 0.0) return 1.0;
  const double z = std::max(z_m, 0.5 * R);
  const double r = R / (4.0 * z);
  return 1.0 / (1.0 - r * r);
}

}  // namespace quadcosim::model
