#include "model/quadrotor.hpp"

#include <algorithm>
#include <cassert>
#include <cmath>

#include "model/attitude.hpp"

namespace quadcosim::model {

Quadrotor::Quadrotor(const VehicleParams& params)
    : params_(params),
      mixer_(mixer_matrix(params)),
      inertia_diag_(params.Ixx_kg_m2, params.Iyy_kg_m2, params.Izz_kg_m2) {
  assert(validate(params).empty());
}

Vector4 Quadrotor::clamp_command(const Vector4& cmd) const {
  Vector4 out;
  for (int i = 0; i < 4; ++i) {
    const double c = std::isfinite(cmd[i]) ? cmd[i] : params_.motor.omega_min_rad_s;
    out[i] = std::clamp(c, params_.motor.omega_min_rad_s, params_.motor.omega_max_rad_s);
  }
  return out;
}

Wrench Quadrotor::wrench(const Vector4& omega) const {
  const Vector4 u = mixer_ * omega.cwiseProduct(omega);
  return {u[0], u.tail<3>()};
}

bool Quadrotor::on_ground(const State& x) const { return x.p_W.z() <= 0.0 && x.v_W.z() <= 0.0; }

StateDerivative Quadrotor::derivative(double /*t_s*/, const State& x, const Vector4& cmd,
                                      const Environment* env) const {
  StateDerivative d;
  const bool ideal = params_.motor.model == MotorModel::kIdeal;
  const Vector4 omega = ideal ? cmd : x.omega_rad_s;

  if (ideal) {
    d.omega_rad_s.setZero();
  } else {
    for (int i = 0; i < 4; ++i) {
      const double err = cmd[i] - x.omega_rad_s[i];
      const double tau = err > 0.0 ? params_.motor.tau_up_s : params_.motor.tau_down_s;
      d.omega_rad_s[i] = err / tau;
    }
  }

  const Wrench f = env ? environment_wrench(omega, x, *env) : wrench(omega);
  const Eigen::Matrix3d R_WB = x.q_WB.toRotationMatrix();
  d.p_W = x.v_W;
  d.v_W = R_WB.col(2) * (f.thrust_N / params_.mass_kg);
  d.v_W.z() -= params_.gravity_m_s2;
  if (env) d.v_W += aero_force_W(params_.aero, R_WB, x.v_W, env->wind_W, omega) / params_.mass_kg;

  const Eigen::Vector3d& w = x.w_B;
  Eigen::Vector3d tau = f.torque_B_Nm;
  if (params_.gyroscopic == GyroscopicModel::kFull) {
    tau -= w.cross(inertia_diag_.cwiseProduct(w));
  }
  d.w_B = tau.cwiseQuotient(inertia_diag_);

  if (on_ground(x) && d.v_W.z() <= 0.0) {
    // Resting on the ground: the normal force and friction cancel the net force and torque.
    d.v_W.setZero();
    d.w_B.setZero();
  }

  // dq/dt = 1/2 q (x) (0, w)
  const Eigen::Quaterniond& q = x.q_WB;
  d.q_WB_wxyz << -0.5 * (q.x() * w.x() + q.y() * w.y() + q.z() * w.z()),
      0.5 * (q.w() * w.x() + q.y() * w.z() - q.z() * w.y()),
      0.5 * (q.w() * w.y() + q.z() * w.x() - q.x() * w.z()),
      0.5 * (q.w() * w.z() + q.x() * w.y() - q.y() * w.x());
  return d;
}

Wrench Quadrotor::environment_wrench(const Vector4& omega, const State& x, const Environment& env) const {
  const Vector4 u = mixer_ * env.rotor_efficiency.cwiseProduct(omega.cwiseProduct(omega));
  return {u[0] * ground_effect_factor(params_.aero, x.p_W.z()), u.tail<3>()};
}

Outputs Quadrotor::outputs(double t_s, const State& x, const Vector4& cmd, const Environment* env) const {
  const StateDerivative d = derivative(t_s, x, clamp_command(cmd), env);
  Eigen::Vector3d a_minus_g = d.v_W;
  a_minus_g.z() += params_.gravity_m_s2;
  return {x.p_W, x.q_WB, x.v_W, x.w_B, x.q_WB.conjugate() * a_minus_g};
}

namespace {

State add_scaled(const State& x, const StateDerivative& d, double h) {
  State y;
  y.p_W = x.p_W + h * d.p_W;
  y.v_W = x.v_W + h * d.v_W;
  y.q_WB.coeffs() = x.q_WB.coeffs();  // Eigen stores (x, y, z, w)
  y.q_WB.w() += h * d.q_WB_wxyz[0];
  y.q_WB.x() += h * d.q_WB_wxyz[1];
  y.q_WB.y() += h * d.q_WB_wxyz[2];
  y.q_WB.z() += h * d.q_WB_wxyz[3];
  y.w_B = x.w_B + h * d.w_B;
  y.omega_rad_s = x.omega_rad_s + h * d.omega_rad_s;
  return y;
}

StateDerivative weighted_sum(const StateDerivative& k1, const StateDerivative& k2,
                             const StateDerivative& k3, const StateDerivative& k4) {
  // (k1 + 2 k2 + 2 k3 + k4) / 6, the RK4 slope.
  auto mix = [](const auto& a, const auto& b, const auto& c, const auto& e) {
    return ((a + 2.0 * b + 2.0 * c + e) / 6.0).eval();
  };
  return {mix(k1.p_W, k2.p_W, k3.p_W, k4.p_W), mix(k1.v_W, k2.v_W, k3.v_W, k4.v_W),
          mix(k1.q_WB_wxyz, k2.q_WB_wxyz, k3.q_WB_wxyz, k4.q_WB_wxyz),
          mix(k1.w_B, k2.w_B, k3.w_B, k4.w_B),
          mix(k1.omega_rad_s, k2.omega_rad_s, k3.omega_rad_s, k4.omega_rad_s)};
}

}  // namespace

void Quadrotor::step(State& x, double t_s, const Vector4& cmd_in, double dt_s, int substeps,
                     const Environment* env) const {
  assert(substeps >= 1);
  const Vector4 cmd = clamp_command(cmd_in);
  const double h = dt_s / substeps;
  for (int s = 0; s < substeps; ++s) {
    const double t = t_s + s * h;
    const StateDerivative k1 = derivative(t, x, cmd, env);
    const StateDerivative k2 = derivative(t + 0.5 * h, add_scaled(x, k1, 0.5 * h), cmd, env);
    const StateDerivative k3 = derivative(t + 0.5 * h, add_scaled(x, k2, 0.5 * h), cmd, env);
    const StateDerivative k4 = derivative(t + h, add_scaled(x, k3, h), cmd, env);
    x = add_scaled(x, weighted_sum(k1, k2, k3, k4), h);
    x.q_WB.normalize();
    if (x.p_W.z() < 0.0) {  // touched down during the step: inelastic impact, held by friction
      x.p_W.z() = 0.0;
      x.v_W.setZero();
      x.w_B.setZero();
    }
  }
  if (params_.motor.model == MotorModel::kIdeal) {
    x.omega_rad_s = cmd;
  } else {
    x.omega_rad_s = clamp_command(x.omega_rad_s);
  }
}

State Quadrotor::initial_state(const Eigen::Vector3d& p_W, double yaw_rad, bool hover) const {
  State x;
  x.p_W = p_W;
  x.q_WB = quaternion_from_euler({0.0, 0.0, yaw_rad});
  if (hover) x.omega_rad_s.setConstant(params_.hover_omega_rad_s());
  return x;
}

}  // namespace quadcosim::model
