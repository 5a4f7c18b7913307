#include "control/inner_loops.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "model/attitude.hpp"
#include "model/mixer.hpp"

namespace quadcosim::control {

namespace {

Eigen::Vector3d vee(const Eigen::Matrix3d& m) { return {m(2, 1), m(0, 2), m(1, 0)}; }

}  // namespace

InnerLoopParams InnerLoopParams::for_vehicle(const model::VehicleParams& vehicle, double period_s) {
  InnerLoopParams p;
  double kw = std::min(30.0, 0.3 / period_s);
  if (vehicle.motor.model != model::MotorModel::kIdeal) {
    kw = std::min(kw, 0.75 / std::max(vehicle.motor.tau_up_s, vehicle.motor.tau_down_s));
  }
  p.rate_bandwidth_rad_s = kw;
  p.attitude_bandwidth_rad_s = kw / 4.0;
  p.velocity_bandwidth_rad_s = kw / 20.0;
  return p;
}

const ParameterTable<InnerLoopParams>& inner_loop_table() {
  using T = ParameterTable<InnerLoopParams>;
  static const T table({
      T::number(
          "inner.rate_bandwidth", "rad/s", 0.1, 1e4,
          "body-rate loop bandwidth K_w: a rate step settles as 1 - exp(-K_w t) (levels ctbr and above)",
          [](auto& p) -> auto& { return p.rate_bandwidth_rad_s; }),
      T::number(
          "inner.attitude_bandwidth", "rad/s", 0.1, 1e4,
          "attitude loop gain K_R: rate setpoint -K_R e_R (levels ctatt and above)",
          [](auto& p) -> auto& { return p.attitude_bandwidth_rad_s; }),
      T::number(
          "inner.velocity_bandwidth", "rad/s", 0.01, 1e3,
          "velocity loop bandwidth K_v: a velocity step settles as 1 - exp(-K_v t) (level velocity)",
          [](auto& p) -> auto& { return p.velocity_bandwidth_rad_s; }),
      T::number(
          "inner.max_tilt", "rad", 0.01, 1.4, "tilt limit of the acceleration the velocity and acceleration levels ask",
          [](auto& p) -> auto& { return p.max_tilt_rad; }),
  });
  return table;
}

InnerLoops::InnerLoops(const model::VehicleParams& vehicle, const InnerLoopParams& params, double period_s)
    : params_(params),
      period_s_(period_s),
      mass_kg_(vehicle.mass_kg),
      gravity_m_s2_(vehicle.gravity_m_s2),
      kt_(vehicle.kt_N_per_rad2_s2),
      omega_min_(vehicle.motor.omega_min_rad_s),
      omega_max_(vehicle.motor.omega_max_rad_s),
      J_(vehicle.inertia_tensor()),
      allocation_(vehicle),
      k_rate_(pole_matched(params.rate_bandwidth_rad_s, period_s)),
      k_velocity_(pole_matched(params.velocity_bandwidth_rad_s, period_s)) {
  if (std::string err = check_inner_loops(params, vehicle, period_s); !err.empty()) throw std::invalid_argument(err);
}

Eigen::Vector3d InnerLoops::rate_torques(const Eigen::Vector3d& w_des_B, const Eigen::Vector3d& w_B) const {
  return J_ * (k_rate_ * (w_des_B - w_B)) + w_B.cross(J_ * w_B);
}

Eigen::Vector3d InnerLoops::attitude_rates(const Eigen::Matrix3d& R_des, const Eigen::Matrix3d& R_WB) const {
  const Eigen::Vector3d e_R = 0.5 * vee(R_des.transpose() * R_WB - R_WB.transpose() * R_des);
  return -params_.attitude_bandwidth_rad_s * e_R;
}

Eigen::Vector3d InnerLoops::velocity_acceleration(const Eigen::Vector3d& v_des_W, const Eigen::Vector3d& v_W) const {
  return k_velocity_ * (v_des_W - v_W);
}

InnerLoops::ThrustAttitude InnerLoops::thrust_attitude(const Eigen::Vector3d& a_des_W, double yaw_rad,
                                                       const Eigen::Matrix3d& R_WB) const {
  ThrustAttitude out;
  Eigen::Vector3d F = mass_kg_ * (a_des_W + Eigen::Vector3d(0.0, 0.0, gravity_m_s2_));
  // The rotors push along +z_B only: no downward force, and the tilt of F limited (its vertical part kept).
  F.z() = std::max(F.z(), 0.0);
  const double horizontal = F.head<2>().norm();
  const double limit = F.z() * std::tan(params_.max_tilt_rad);
  if (horizontal > limit) {
    F.head<2>() *= horizontal > 0.0 ? limit / horizontal : 0.0;
    out.tilt_saturated = true;
  }
  const double norm = F.norm();
  const Eigen::Vector3d b3 = norm > 0.0 ? Eigen::Vector3d(F / norm) : Eigen::Vector3d::UnitZ();
  const Eigen::Vector3d b1c(std::cos(yaw_rad), std::sin(yaw_rad), 0.0);
  const Eigen::Vector3d b2 = b3.cross(b1c).normalized();  // b3 is never horizontal: tilt <= 1.4 rad
  out.R_des.col(0) = b2.cross(b3);
  out.R_des.col(1) = b2;
  out.R_des.col(2) = b3;
  out.thrust_N = std::max(0.0, F.dot(R_WB.col(2)));
  return out;
}

Allocation InnerLoops::allocate_wrench(const Eigen::Vector4d& U) const {
  return allocation_.allocate(U, omega_min_, omega_max_);
}

Allocation InnerLoops::rotor_thrusts(const Eigen::Vector4d& T_N) const {
  Allocation out;  // four rotors: the level is refused for other vehicles (sim::check_command)
  for (int i = 0; i < 4; ++i) {
    const double omega = std::sqrt(std::max(0.0, T_N[i]) / kt_);
    out.omega_rad_s[i] = std::clamp(omega, omega_min_, omega_max_);
    out.saturated[i] = !(omega >= omega_min_ && omega <= omega_max_) || T_N[i] < 0.0;
  }
  return out;
}

InnerLoopOutput InnerLoops::step(const LevelCommand& sp, const model::State& x) const {
  InnerLoopOutput out;
  const Eigen::Vector4d& s = sp.value;
  if (sp.level == CommandLevel::kRotorSpeeds) {
    for (int i = 0; i < 4; ++i) {
      out.allocation.omega_rad_s[i] = std::clamp(s[i], omega_min_, omega_max_);
      out.allocation.saturated[i] = !(s[i] >= omega_min_ && s[i] <= omega_max_);
    }
    return out;
  }
  if (sp.level == CommandLevel::kRotorThrusts) {
    out.allocation = rotor_thrusts(s);
    return out;
  }
  double thrust = s[0];
  Eigen::Vector3d w_des = s.tail<3>();
  Eigen::Vector3d torque = s.tail<3>();
  switch (sp.level) {
    case CommandLevel::kVelocity:
    case CommandLevel::kAcceleration: {
      const Eigen::Matrix3d R = x.q_WB.toRotationMatrix();
      const Eigen::Vector3d a_des = sp.level == CommandLevel::kVelocity ? velocity_acceleration(s.head<3>(), x.v_W)
                                                                        : Eigen::Vector3d(s.head<3>());
      const ThrustAttitude ta = thrust_attitude(a_des, s[3], R);
      out.tilt_saturated = ta.tilt_saturated;
      thrust = ta.thrust_N;
      w_des = attitude_rates(ta.R_des, R);
      torque = rate_torques(w_des, x.w_B);
      break;
    }
    case CommandLevel::kCtatt: {
      const Eigen::Matrix3d R = x.q_WB.toRotationMatrix();
      const Eigen::Matrix3d R_des = model::quaternion_from_euler({s[1], s[2], s[3]}).toRotationMatrix();
      w_des = attitude_rates(R_des, R);
      torque = rate_torques(w_des, x.w_B);
      break;
    }
    case CommandLevel::kCtbr: torque = rate_torques(w_des, x.w_B); break;
    default:  // kCttm: the torques as given
      break;
  }
  out.U << thrust, torque;
  out.allocation = allocate_wrench(out.U);
  return out;
}

}  // namespace quadcosim::control
