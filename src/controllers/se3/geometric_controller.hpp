// The geometric tracking controller on SE(3) of Lee, Leok and McClamroch (2010), "Geometric tracking
// control of a quadrotor UAV on SE(3)"; registry type "se3" (docs/controllers.md). Frames: world ENU
// (z up, so gravity is -g e3 and the thrust feedforward is +m g e3), body FLU; R = R_WB rotates body
// vectors into the world, e3 = (0, 0, 1).
//
// Position mode: e_x = p - p_d, e_v = v - v_d, F = -k_x o e_x - k_v o e_v + m g e3 + m a_d [N]
// (o: per-axis product), b3d = F/|F| (optionally tilt-limited), b1c = (cos psi_d, sin psi_d, 0),
// b2d = b3d x b1c / |b3d x b1c|, R_d = [b2d x b3d, b2d, b3d], thrust f = F . R e3 (>= 0); Omega_d from
// the reference's jerk and yaw rate by differential flatness (geometric_controller.cpp); the reference
// carries no snap, so dOmega_d/dt is taken as zero.
// Attitude mode (the paper's step tests): R_d = R(roll_d, pitch_d, yaw_d), Omega_d = 0, thrust from a
// z loop f = (m (g + a_d,z) - k_x,z e_z - k_v,z e_vz) / max((R e3)_z, min_cos_tilt).
// Both: e_R = 1/2 vee(R_d^T R - R^T R_d), e_Omega = Omega - R^T R_d Omega_d,
// M = -k_R o e_R - k_Omega o e_Omega + Omega x J Omega - J (hat(Omega) R^T R_d Omega_d) [N m], then the
// yaw torque is cut to what the rotors can give besides (f, M_x, M_y) and U = (f, M) is allocated
// (control::RotorAllocation: the mixer inverse, or its pseudo-inverse for more than four rotors;
// clamped speeds).
//
// Default gains, for the paper's Table 1 vehicle (model::VehicleParams{}) flown at a 50 Hz control
// rate with first-order motors (tau 0.02 s up, 0.04 s down): the loop sees about 0.01 s of hold delay
// and 0.02-0.04 s of motor lag, i.e. roughly 0.04 s of phase lag, so each loop is a damped second-order
// design scaled by the inertia or mass:
//   attitude roll/pitch: omega_n = 10 rad/s, zeta = 0.8: k_R = J omega_n^2, k_Omega = 2 zeta J omega_n
//     (crossover ~17 rad/s, where the 0.04 s lag costs ~39 deg of the PD's ~70 deg of phase margin);
//   yaw: omega_n = 1 rad/s, zeta = 1: the rotors' drag torque gives the Table 1 vehicle only about
//     9e-3 N m of yaw torque at hover (0.18 rad/s^2 of yaw acceleration), so a stiffer yaw loop saturates
//     and overshoots a large heading error (at omega_n = 3 rad/s a 170 deg yaw error overshot to
//     -99 deg and still swung back to +42 deg at 17 s; at 1 rad/s it settles in 12 s without saturating);
//   position: omega_p = 2.5 rad/s horizontally and 3 rad/s vertically, zeta = 1 (a quarter or less of
//     the attitude bandwidth, so the attitude loop follows b3d): k_x = m omega_p^2, k_v = 2 zeta m omega_p.
// Other vehicles: the same design, k_R and k_Omega scaled by their inertia and k_x, k_v by their mass
// (GeometricParams::for_vehicle; a controller made for a vehicle starts from these gains).
#pragma once

#include <Eigen/Core>
#include <string>

#include "control/allocation.hpp"
#include "control/controller.hpp"
#include "model/vehicle_params.hpp"

namespace quadcosim::controllers {

struct GeometricParams {
  Eigen::Vector3d k_x{12.25, 12.25, 17.64};         ///< position gains, world x, y, z [N/m]
  Eigen::Vector3d k_v{9.8, 9.8, 11.76};             ///< velocity gains, world x, y, z [N s/m]
  Eigen::Vector3d k_R{1.49, 1.53, 0.0532};          ///< attitude gains, body x, y, z [N m/rad]
  Eigen::Vector3d k_Omega{0.2384, 0.2448, 0.1064};  ///< body rate gains, body x, y, z [N m s/rad]
  /// Largest angle [rad] between b3d and e3 in position mode; beyond it the horizontal part of F is cut
  /// (tilt_saturated). pi: no limit.
  double max_tilt_rad = 1.0;
  /// Attitude mode: floor on (R e3)_z in the thrust's tilt compensation [-] (control/altitude_pd.hpp).
  double min_cos_tilt = 0.5;

  /// The default design above for `vehicle`: k_x, k_v times m / m_Table1, k_R and k_Omega per body axis
  /// times J_ii / J_ii,Table1 (the same loop bandwidths and damping). The Table 1 vehicle gets the
  /// defaults exactly.
  static GeometricParams for_vehicle(const model::VehicleParams& vehicle);
};

/// The parts of one step that tests and tools may want to see (all in the conventions above).
struct GeometricTerms {
  Eigen::Vector3d e_x_W = Eigen::Vector3d::Zero();      ///< [m]
  Eigen::Vector3d e_v_W = Eigen::Vector3d::Zero();      ///< [m/s]
  Eigen::Vector3d e_R = Eigen::Vector3d::Zero();        ///< [rad] (sin of the angle for one axis)
  Eigen::Vector3d e_Omega_B = Eigen::Vector3d::Zero();  ///< [rad/s]
  Eigen::Vector3d Omega_d_B = Eigen::Vector3d::Zero();  ///< desired body rates in the desired frame [rad/s]
  Eigen::Matrix3d R_d = Eigen::Matrix3d::Identity();    ///< desired attitude, body -> world
  double yaw_torque_cut_Nm = 0.0;                       ///< requested M_z minus the M_z allocated [N m]
};

class GeometricController : public control::ControllerWith<GeometricController, GeometricParams> {
 public:
  static constexpr std::string_view kType = "se3";
  static constexpr std::string_view kDescription = "geometric tracking on SE(3) (Lee, Leok, McClamroch 2010)";

  /// The controller for `vehicle` (mass, gravity, inertia, mixer, motor speed limits). Throws
  /// std::invalid_argument when the vehicle's mixer is singular.
  /// With the gains GeometricParams::for_vehicle(vehicle).
  explicit GeometricController(const model::VehicleParams& vehicle);
  GeometricController(const model::VehicleParams& vehicle, const GeometricParams& params);

  std::string_view type() const override { return kType; }
  /// "e_x.x" .. "e_v.z" [m, m/s], "e_R.x" .. "e_R.z" [rad], "e_Omega.x" .. "e_Omega.z" [rad/s],
  /// "thrust" [N], "yaw_torque_cut" [N m].
  std::span<const std::string> output_names() const override;
  void reset() override {}  // no internal state
  void step(const control::Observation& observation, const control::Reference& reference, double dt_s,
            control::ControllerOutput& out) override;

  const model::VehicleParams& vehicle() const { return vehicle_; }
  /// The terms of the last step().
  const GeometricTerms& terms() const { return terms_; }

 protected:
  const control::ParameterTable<GeometricParams>& table() const override;
  /// The gains are used as given: nothing is designed from them (the mixer inverse, from the vehicle, is
  /// made once by the constructor).
  void configure(const GeometricParams&) override {}

 private:
  model::VehicleParams vehicle_;
  Eigen::Matrix3d J_;
  Eigen::Matrix4d mixer_inverse_ = Eigen::Matrix4d::Zero();  ///< four rotors: M^-1 by full-pivot LU
  control::RotorAllocation allocation_;  ///< the layout's allocation (mixer_inverse_'s, or M^+ for more rotors)
  GeometricTerms terms_;
};

/// e_R = 1/2 vee(R_d^T R - R^T R_d): for R = R_d exp(theta hat(a)), sin(theta) a.
Eigen::Vector3d attitude_error_vector(const Eigen::Matrix3d& R_d, const Eigen::Matrix3d& R);

}  // namespace quadcosim::controllers
