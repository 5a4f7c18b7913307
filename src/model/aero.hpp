// Aerodynamic effects on the airframe and the environment the plant flies in. All off by default:
// with zero coefficients and no Environment the plant is exactly the paper's model.
//
// Forces act at the centre of mass (no aerodynamic moments are modelled). With the air-relative
// velocity v_r = v_W - wind_W and its body components v_rB = R_BW v_r:
//  - linear body drag      F_B = -D_lin ∘ v_rB                      (per body axis) [N]
//  - quadratic body drag   F_B = -D_quad ∘ |v_rB| ∘ v_rB             (per body axis) [N]
//  - rotor (induced) drag  F_B = -k_rd (Σ ω_i) (v_rB,x, v_rB,y, 0)   (blade flapping / induced drag,
//    proportional to rotor speed and in-plane airspeed: Faessler, Franchi, Scaramuzza, RA-L 2018;
//    Kai, Allibert, Hua, Hamel, IFAC 2017)
//  - ground effect on the collective thrust (Cheeseman and Bennett, ARC R&M 3021, 1955):
//    T_IGE / T_OGE = 1 / (1 - (R / 4z)^2), with z floored at R/2 (factor at most 4/3).
#pragma once

#include <Eigen/Core>
#include <string>

namespace quadcosim::model {

struct AeroParams {
  Eigen::Vector3d linear_drag_N_s_m = Eigen::Vector3d::Zero();       ///< D_lin per body axis [N/(m/s)]
  Eigen::Vector3d quadratic_drag_N_s2_m2 = Eigen::Vector3d::Zero();  ///< D_quad per body axis [N/(m/s)^2]
  double rotor_drag_N_s_m_per_rad_s = 0.0;    ///< k_rd [N/((m/s) (rad/s))], summed over the rotors
  double ground_effect_rotor_radius_m = 0.0;  ///< rotor radius R [m] for ground effect; 0: off

  /// True when any coefficient is non-zero (the plant then takes the environment path).
  bool active() const;
};

/// What the air and the rotors do to the vehicle over one plant tick (held constant across it).
struct Environment {
  Eigen::Vector3d wind_W = Eigen::Vector3d::Zero();            ///< air velocity in the world frame [m/s]
  Eigen::Vector4d rotor_efficiency = Eigen::Vector4d::Ones();  ///< per-rotor factor on thrust and drag torque [0, 1]
};

/// Drag force in the world frame [N] for attitude R_WB, velocity v_W, wind wind_W, rotor speeds.
Eigen::Vector3d aero_force_W(const AeroParams& a, const Eigen::Matrix3d& R_WB, const Eigen::Vector3d& v_W,
                             const Eigen::Vector3d& wind_W, const Eigen::Vector4d& omega_rad_s);

/// Ground-effect thrust factor at height z_m [m] (1 when off).
double ground_effect_factor(const AeroParams& a, double z_m);

// The coefficients' accepted ranges are declared in the vehicle parameter table
// (vehicle_params.hpp, `aero.*`) and checked by validate(const VehicleParams&).

}  // namespace quadcosim::model
