// The inner loops that fly a vehicle at a command level above rotor speeds (control/command_level.hpp).
// They run on the plant side at the PLANT rate, on every plant tick, on the vehicle's true state (what
// an onboard estimator would give them: no sensor noise, no delay), and hold their output over the tick
// as the motors' zero-order hold does. Each level enters the chain where its setpoint lives:
//
//   velocity -> acceleration:   a_des = K_v' (v_des - v)                               (world, P)
//   acceleration -> ctatt:      F = m (a_des + g e3), tilt of F limited to max_tilt; U1 = F . R e3,
//                               R_des = [b1 b2 b3], b3 = F / |F|, b1 from the yaw (as the se3 controller)
//   ctatt -> ctbr:              w_des = -K_R e_R, e_R = 1/2 vee(R_des^T R - R^T R_des)
//   ctbr -> cttm:               M = J K_w' (w_des - w) + w x J w
//   cttm -> rotor speeds:       the layout's allocation, M^-1 U for four rotors and M^+ U for more
//                               (control/allocation.hpp): the only place that knows the rotors;
//                               rotor_thrusts (four-rotor vehicles only): omega_i = sqrt(T_i / k_t)
//
// The gains are bandwidths [rad/s], scaled by the vehicle's mass and inertia tensor, so one set serves
// every vehicle. The first-order loops (velocity, body rate) use the pole-matched discrete gain
// K' = (1 - exp(-K h)) / h for the plant period h: on an ideal vehicle their error then decays as
// exp(-K t) exactly at the ticks. The attitude loop on top of the rate loop is the second-order
// e'' + K_w e' + K_w K_R e = 0 (critically damped at K_w = 4 K_R, the defaults). The design is checked
// for the plant period when it is made (check_inner_loops): a gain the sampled loop cannot hold is
// refused by name.
#pragma once

#include <Eigen/Core>
#include <cmath>
#include <string>

#include "control/allocation.hpp"
#include "control/command_level.hpp"
#include "control/parameters.hpp"
#include "model/quadrotor.hpp"

namespace quadcosim::control {

struct InnerLoopParams {
  double rate_bandwidth_rad_s = 30.0;     ///< K_w: body-rate loop, time constant 1 / K_w
  double attitude_bandwidth_rad_s = 7.5;  ///< K_R: attitude error -> rate setpoint
  double velocity_bandwidth_rad_s = 1.5;  ///< K_v: velocity loop, time constant 1 / K_v
  double max_tilt_rad = 0.7;              ///< tilt limit of the velocity and acceleration levels

  /// The defaults for a vehicle flown at plant period `period_s`: K_w = min(30 rad/s, 0.3 / h,
  /// 0.75 / tau_motor with a first-order motor), K_R = K_w / 4 (the cascade critically damped),
  /// K_v = K_R / 5. At the paper's 100 Hz on its ideal motors: 30, 7.5 and 1.5 rad/s.
  static InnerLoopParams for_vehicle(const model::VehicleParams& vehicle, double period_s);
};

/// The declared parameters: inner.rate_bandwidth, inner.attitude_bandwidth, inner.velocity_bandwidth,
/// inner.max_tilt.
const ParameterTable<InnerLoopParams>& inner_loop_table();

/// The pole-matched discrete gain K' = (1 - exp(-K h)) / h of a first-order loop of bandwidth k [rad/s]
/// at period h [s]: its error decays as exp(-K t) exactly at the ticks.
inline double pole_matched(double k_rad_s, double h_s) { return -std::expm1(-k_rad_s * h_s) / h_s; }

/// "" when the loops are stable at the plant period `period_s` on `vehicle`, else the gain at fault and
/// why: K_w h <= 1 (the rate loop's time constant at least one tick); K_w tau_motor <= 1 with a
/// first-order motor (its lag keeps the rate loop's damping >= 0.5); the discrete closed loops of the
/// linearised single axis (attitude on the rate loop; velocity on both) with their eigenvalues inside
/// the unit circle (a spectral radius >= 1 names the attitude or the velocity bandwidth).
std::string check_inner_loops(const InnerLoopParams& params, const model::VehicleParams& vehicle, double period_s);

/// What a tick's inner loops decided.
struct InnerLoopOutput {
  Allocation allocation;                        ///< rotor speeds and which rotors were clamped
  Eigen::Vector4d U = Eigen::Vector4d::Zero();  ///< U1 [N], U2..U4 [N m] asked of the allocation
  bool tilt_saturated = false;                  ///< the tilt limit cut a velocity/acceleration setpoint
  bool saturated() const { return tilt_saturated || allocation.saturated.any(); }
};

class InnerLoops {
 public:
  /// Throws std::invalid_argument with check_inner_loops' reason when the gains do not fit.
  InnerLoops(const model::VehicleParams& vehicle, const InnerLoopParams& params, double period_s);

  /// The rotor speeds for `sp` at the vehicle state `x` (held over the next plant tick).
  InnerLoopOutput step(const LevelCommand& sp, const model::State& x) const;

  /// The stages, each on its own (tests and hosts that want one level's maths).
  /// Body torques [N m] for the rate setpoint.
  Eigen::Vector3d rate_torques(const Eigen::Vector3d& w_des_B, const Eigen::Vector3d& w_B) const;
  /// Body-rate setpoint [rad/s] that turns R_WB towards R_des.
  Eigen::Vector3d attitude_rates(const Eigen::Matrix3d& R_des, const Eigen::Matrix3d& R_WB) const;
  /// World acceleration setpoint [m/s^2] for the velocity setpoint.
  Eigen::Vector3d velocity_acceleration(const Eigen::Vector3d& v_des_W, const Eigen::Vector3d& v_W) const;
  struct ThrustAttitude {
    double thrust_N = 0.0;
    Eigen::Matrix3d R_des = Eigen::Matrix3d::Identity();
    bool tilt_saturated = false;
  };
  /// Collective thrust and attitude for a world acceleration (gravity excluded) and a yaw.
  ThrustAttitude thrust_attitude(const Eigen::Vector3d& a_des_W, double yaw_rad, const Eigen::Matrix3d& R_WB) const;
  /// Rotor speeds for a wrench U (clamped to the motors' range, flagged).
  Allocation allocate_wrench(const Eigen::Vector4d& U) const;
  /// Rotor speeds for rotor thrusts T_i [N] of a four-rotor vehicle: sqrt(T_i / k_t), clamped, flagged.
  Allocation rotor_thrusts(const Eigen::Vector4d& T_N) const;

  const InnerLoopParams& params() const { return params_; }
  double period_s() const { return period_s_; }

 private:
  InnerLoopParams params_;
  double period_s_;
  double mass_kg_, gravity_m_s2_, kt_, omega_min_, omega_max_;
  Eigen::Matrix3d J_;
  RotorAllocation allocation_;
  double k_rate_, k_velocity_;  ///< the pole-matched discrete gains [1/s]
};

}  // namespace quadcosim::control
