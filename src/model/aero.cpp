#include "model/aero.hpp"

#include <algorithm>
#include <cmath>
#include <string>

namespace quadcosim::model {

bool AeroParams::rotor_aero_active() const {
  return rotor_aero == RotorAero::kOn &&
         (rotor_drag_k_d != 0.0 || inflow_k_z != 0.0 || flapping_k_flap != 0.0 || translational_lift_k_h != 0.0);
}

bool AeroParams::active() const {
  return !linear_drag_N_s_m.isZero(0.0) || !quadratic_drag_N_s2_m2.isZero(0.0) || rotor_drag_N_s_m_per_rad_s != 0.0 ||
         ground_effect_rotor_radius_m != 0.0 || rotor_aero_active();
}

Eigen::Vector3d aero_force_W(const AeroParams& a, const Eigen::Matrix3d& R_WB, const Eigen::Vector3d& v_W,
                             const Eigen::Vector3d& wind_W, const RotorVector& omega_rad_s) {
  const Eigen::Vector3d v_rB = R_WB.transpose() * (v_W - wind_W);
  Eigen::Vector3d F_B = -a.linear_drag_N_s_m.cwiseProduct(v_rB) -
                        a.quadratic_drag_N_s2_m2.cwiseProduct(v_rB.cwiseAbs()).cwiseProduct(v_rB);
  if (a.rotor_drag_N_s_m_per_rad_s != 0.0) {
    // Four rotors: summed as the fixed-size vector sums (the paper-era numbers, bit for bit).
    const double sum = omega_rad_s.size() == 4 ? Eigen::Vector4d(omega_rad_s.head<4>()).cwiseAbs().sum()
                                               : omega_rad_s.cwiseAbs().sum();
    const double k = a.rotor_drag_N_s_m_per_rad_s * sum;
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

BodyWrench rotor_aero_wrench_B(const AeroParams& a, const Eigen::Ref<const Eigen::Matrix3Xd>& rotor_positions_B,
                               const Eigen::Vector3d& v_rB, const Eigen::Vector3d& w_B,
                               const Eigen::Ref<const Eigen::VectorXd>& omega_rad_s,
                               const Eigen::Ref<const Eigen::VectorXd>& efficiency) {
  BodyWrench total;
  for (Eigen::Index i = 0; i < rotor_positions_B.cols(); ++i) {
    const Eigen::Vector3d r = rotor_positions_B.col(i);
    const Eigen::Vector3d v = v_rB + w_B.cross(r);  // the hub's velocity through the air
    const double w = efficiency[i] * std::abs(omega_rad_s[i]);
    // H-force in the rotor plane, inflow along the axis, translational lift along +z_B: at the hub.
    const Eigen::Vector3d F(
        -w * a.rotor_drag_k_d * v.x(), -w * a.rotor_drag_k_d * v.y(),
        -w * a.inflow_k_z * v.z() + efficiency[i] * a.translational_lift_k_h * (v.x() * v.x() + v.y() * v.y()));
    total.force_B += F;
    total.torque_B += r.cross(F);
    // Flapping: -k_flap w (e_z x v), e_z x v = (-v_y, v_x, 0).
    total.torque_B.x() += w * a.flapping_k_flap * v.y();
    total.torque_B.y() -= w * a.flapping_k_flap * v.x();
  }
  return total;
}

const char* to_string(RotorAero mode) { return mode == RotorAero::kOn ? "true" : "false"; }

}  // namespace quadcosim::model
