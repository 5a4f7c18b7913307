// Aerodynamic effects on the airframe and the environment the plant flies in. All off by default:
// with zero coefficients and no Environment the plant is exactly the paper's model.
//
// The lumped terms act at the centre of mass. With the air-relative velocity v_r = v_W - wind_W and
// its body components v_rB = R_BW v_r:
//  - linear body drag      F_B = -D_lin ∘ v_rB                      (per body axis) [N]
//  - quadratic body drag   F_B = -D_quad ∘ |v_rB| ∘ v_rB             (per body axis) [N]
//  - rotor (induced) drag  F_B = -k_rd (Σ ω_i) (v_rB,x, v_rB,y, 0)   (blade flapping / induced drag,
//    proportional to rotor speed and in-plane airspeed: Faessler, Franchi, Scaramuzza, RA-L 2018;
//    Kai, Allibert, Hua, Hamel, IFAC 2017)
//  - ground effect on the collective thrust (Cheeseman and Bennett, ARC R&M 3021, 1955):
//    T_IGE / T_OGE = 1 / (1 - (R / 4z)^2), with z floored at R/2 (factor at most 4/3).
//
// Per-rotor aerodynamics (rotor_aero on; rotor_aero_wrench_B): at each hub i, at r_i in the body
// frame, the air-relative hub velocity v_i = v_rB + w_B x r_i, and with |omega_i| the rotor speed
// and eta_i its efficiency (Environment::rotor_efficiency):
//  - rotor drag (H-force) and induced inflow  F_i = -eta_i |omega_i| diag(k_d, k_d, k_z) v_i
//    (Svacha, Mohta, Kumar, ICUAS 2017; RotorPy, Folk et al. 2023), acting at the hub: moment r_i x F_i;
//  - blade flapping  M_i = -eta_i k_flap |omega_i| (e_z x v_i): the disc tilts away from the relative
//    wind and pitches the vehicle away from it (nose up in forward flight);
//  - translational lift  dT_i = eta_i k_h (v_i,x^2 + v_i,y^2) along +z_B, at the hub.
// k_d is the lumped rotor_drag_N_s_m_per_rad_s taken to the hubs (the same coefficient; validate()
// refuses both at once). docs/model.md, "Per-rotor aerodynamics".
#pragma once

#include <Eigen/Core>
#include <string>

#include <string_view>
#include "model/rotor_vector.hpp"

namespace quadcosim::model {

/// Whether the per-rotor terms act (their coefficients may be set and left off, as the presets do).
enum class RotorAero { kOff, kOn };

struct AeroParams {
  Eigen::Vector3d linear_drag_N_s_m = Eigen::Vector3d::Zero();       ///< D_lin per body axis [N/(m/s)]
  Eigen::Vector3d quadratic_drag_N_s2_m2 = Eigen::Vector3d::Zero();  ///< D_quad per body axis [N/(m/s)^2]
  double rotor_drag_N_s_m_per_rad_s = 0.0;    ///< k_rd [N/((m/s) (rad/s))], summed over the rotors
  double ground_effect_rotor_radius_m = 0.0;  ///< rotor radius R [m] for ground effect; 0: off
  RotorAero rotor_aero = RotorAero::kOff;     ///< the per-rotor terms below act only when kOn
  double rotor_drag_k_d = 0.0;                ///< k_d [N/((m/s) (rad/s))], per rotor, in the rotor plane
  double inflow_k_z = 0.0;                    ///< k_z [N/((m/s) (rad/s))], per rotor, along z_B
  double flapping_k_flap = 0.0;               ///< k_flap [N m/((m/s) (rad/s))], per rotor
  double translational_lift_k_h = 0.0;        ///< k_h [N/(m/s)^2], per rotor

  /// True when rotor_aero is on and any per-rotor coefficient is non-zero.
  bool rotor_aero_active() const;
  /// True when any coefficient acts (the plant then takes the environment path).
  bool active() const;
};

/// A force and a moment about the centre of mass, both in the body frame.
struct BodyWrench {
  Eigen::Vector3d force_B = Eigen::Vector3d::Zero();   ///< [N]
  Eigen::Vector3d torque_B = Eigen::Vector3d::Zero();  ///< [N m]
};

/// What the air and the rotors do to the vehicle over one plant tick (held constant across it).
struct Environment {
  Eigen::Vector3d wind_W = Eigen::Vector3d::Zero();  ///< air velocity in the world frame [m/s]
  /// Per-rotor factor on thrust and drag torque [0, 1]; all kMaxRotors entries (the model reads its N).
  RotorVector rotor_efficiency = RotorVector::Ones(kMaxRotors);
};

/// Drag force in the world frame [N] for attitude R_WB, velocity v_W, wind wind_W, rotor speeds.
Eigen::Vector3d aero_force_W(const AeroParams& a, const Eigen::Matrix3d& R_WB, const Eigen::Vector3d& v_W,
                             const Eigen::Vector3d& wind_W, const RotorVector& omega_rad_s);

/// Ground-effect thrust factor at height z_m [m] (1 when off).
double ground_effect_factor(const AeroParams& a, double z_m);

/// The per-rotor terms' wrench (the header's list) for the rotors at the columns of
/// rotor_positions_B [m], turning at omega_rad_s with efficiencies `efficiency` (one entry per rotor),
/// for the air-relative velocity v_rB [m/s] and body rate w_B [rad/s], both in the body frame. Reads
/// the coefficients whether or not rotor_aero is on (the caller asks rotor_aero_active()).
BodyWrench rotor_aero_wrench_B(const AeroParams& a, const Eigen::Ref<const Eigen::Matrix3Xd>& rotor_positions_B,
                               const Eigen::Vector3d& v_rB, const Eigen::Vector3d& w_B,
                               const Eigen::Ref<const Eigen::VectorXd>& omega_rad_s,
                               const Eigen::Ref<const Eigen::VectorXd>& efficiency);

const char* to_string(RotorAero mode);

// The coefficients' accepted ranges are declared in the vehicle parameter table
// (vehicle_params.hpp, `aero.*`) and checked by validate(const VehicleParams&).

}  // namespace quadcosim::model
