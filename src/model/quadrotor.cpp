#include "model/quadrotor.hpp"

#include <algorithm>
#include <cassert>
#include <cmath>

#include "model/attitude.hpp"

namespace quadcosim::model {

Quadrotor::Quadrotor(const VehicleParams& params)
    : params_(params),
      mixer_(mixer_matrix(params)),
      reciprocals_(1.0 / params.mass_kg, 1.0 / params.Ixx_kg_m2, 1.0 / params.Iyy_kg_m2, 1.0 / params.Izz_kg_m2) {
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

namespace {

// The rigid body's part of the state as plain doubles, for the hot path of step(): p_W (0-2), v_W
// (3-5), q_WB as w, x, y, z (6-9), w_B (10-12).
constexpr int kRigid = 13;
using Rigid = double[kRigid];

void pack(const State& x, Rigid r) {
  for (int i = 0; i < 3; ++i) {
    r[i] = x.p_W[i];
    r[3 + i] = x.v_W[i];
    r[10 + i] = x.w_B[i];
  }
  r[6] = x.q_WB.w();
  r[7] = x.q_WB.x();
  r[8] = x.q_WB.y();
  r[9] = x.q_WB.z();
}

void unpack(const Rigid r, State& x) {
  x.p_W = {r[0], r[1], r[2]};
  x.v_W = {r[3], r[4], r[5]};
  x.q_WB = Eigen::Quaterniond(r[6], r[7], r[8], r[9]);
  x.w_B = {r[10], r[11], r[12]};
}

/// What the rigid body's derivative needs besides the state: the rotors' wrench (collective thrust per
/// unit mass [m/s^2], body torque [N m]), an optional extra acceleration in the world frame [m/s^2]
/// (air drag), and the vehicle's constants.
struct RigidInputs {
  double thrust_per_mass;
  double torque_B[3];
  const Eigen::Vector3d* accel_W;
  double gravity;
  double inertia[3];
  double inv_inertia[3];
  bool gyroscopic;
};

/// dv_W/dt, eq. (7): the thrust along R_WB's third column (formed as Eigen's toRotationMatrix()
/// forms it) per unit mass, gravity, and the extra acceleration if any, for the attitude q (w, x, y,
/// z) in y[6..9]. `held` tells whether the ground holds the vehicle (resting on z = 0 with the net
/// force pointing down), in which case the acceleration is zero.
inline Eigen::Vector3d linear_acceleration(const double* y, const RigidInputs& in, bool& held) {
  const double qw = y[6], qx = y[7], qy = y[8], qz = y[9];
  const double tx = 2.0 * qx, ty = 2.0 * qy, tz = 2.0 * qz;
  double ax = (tz * qx + ty * qw) * in.thrust_per_mass;
  double ay = (tz * qy - tx * qw) * in.thrust_per_mass;
  double az = (1.0 - (tx * qx + ty * qy)) * in.thrust_per_mass - in.gravity;
  if (in.accel_W) {
    ax += in.accel_W->x();
    ay += in.accel_W->y();
    az += in.accel_W->z();
  }
  held = y[2] <= 0.0 && y[5] <= 0.0 && az <= 0.0;
  if (held) return Eigen::Vector3d::Zero();
  return {ax, ay, az};
}

/// The equations of Quadrotor::derivative() on 13 plain doubles (y -> d), so that step() can run RK4
/// on them: translation (linear_acceleration); rotation, eq. (8) (or (11)), the gyroscopic term as
/// Eigen's cross() forms it, times 1/I (a product, not a division: shorter latency on every RK4
/// stage); ground contact; dq/dt = 1/2 q (x) (0, w).
inline void rigid_derivative(const double* __restrict y, const RigidInputs& in, double* __restrict d) {
  bool held = false;
  const Eigen::Vector3d a = linear_acceleration(y, in, held);
  const double qw = y[6], qx = y[7], qy = y[8], qz = y[9];
  const double wx = y[10], wy = y[11], wz = y[12];
  double tau_x = in.torque_B[0], tau_y = in.torque_B[1], tau_z = in.torque_B[2];
  if (in.gyroscopic) {
    const double Iwx = in.inertia[0] * wx, Iwy = in.inertia[1] * wy, Iwz = in.inertia[2] * wz;
    tau_x -= wy * Iwz - wz * Iwy;
    tau_y -= wz * Iwx - wx * Iwz;
    tau_z -= wx * Iwy - wy * Iwx;
  }
  double dwx = tau_x * in.inv_inertia[0], dwy = tau_y * in.inv_inertia[1], dwz = tau_z * in.inv_inertia[2];
  if (held) {  // resting on the ground: the normal force and friction cancel the net force and torque
    dwx = dwy = dwz = 0.0;
  }
  d[0] = y[3];
  d[1] = y[4];
  d[2] = y[5];
  d[3] = a.x();
  d[4] = a.y();
  d[5] = a.z();
  d[6] = -0.5 * (qx * wx + qy * wy + qz * wz);
  d[7] = 0.5 * (qw * wx + qy * wz - qz * wy);
  d[8] = 0.5 * (qw * wy + qz * wx - qx * wz);
  d[9] = 0.5 * (qw * wz + qx * wy - qy * wx);
  d[10] = dwx;
  d[11] = dwy;
  d[12] = dwz;
}

RigidInputs rigid_inputs(const VehicleParams& p, const Eigen::Vector4d& reciprocals, const Wrench& f,
                         const Eigen::Vector3d* accel_W) {
  return {f.thrust_N * reciprocals[0],
          {f.torque_B_Nm.x(), f.torque_B_Nm.y(), f.torque_B_Nm.z()},
          accel_W,
          p.gravity_m_s2,
          {p.Ixx_kg_m2, p.Iyy_kg_m2, p.Izz_kg_m2},
          {reciprocals[1], reciprocals[2], reciprocals[3]},
          p.gyroscopic == GyroscopicModel::kFull};
}

/// Scales q (w, x, y, z) to unit norm: |q|^2 summed as Eigen sums (x, y, z, w) in pairs, then one
/// division and four products (end_substep: the state's quaternion after every RK4 step).
void normalize_quaternion(double& w, double& x, double& y, double& z) {
  const double n2 = (x * x + z * z) + (y * y + w * w);
  if (!(n2 > 0.0)) return;
  const double inv_n = 1.0 / std::sqrt(n2);
  w *= inv_n;
  x *= inv_n;
  y *= inv_n;
  z *= inv_n;
}

/// The end of an RK4 step, in both drivers: the quaternion back to unit norm; a vehicle that went
/// below z = 0 during the step touched down (inelastic impact, held by friction).
void end_substep(Rigid r) {
  // On scalars: an Eigen quaternion here costs two failed store-to-load forwards per step.
  normalize_quaternion(r[6], r[7], r[8], r[9]);
  if (r[2] < 0.0) {
    r[2] = 0.0;
    r[3] = r[4] = r[5] = 0.0;
    r[10] = r[11] = r[12] = 0.0;
  }
}

/// q.conjugate() * v as Eigen computes it (u = 2 (q_vec x v), v + w u + q_vec x u, with q_vec
/// negated), on scalars read one by one: the state was just stored that way by step(), and Eigen's
/// paired loads of it would wait for those stores.
Eigen::Vector3d rotate_by_inverse(const Eigen::Quaterniond& q, const Eigen::Vector3d& v) {
  const double qw = q.w(), qx = -q.x(), qy = -q.y(), qz = -q.z();
  double ux = qy * v.z() - qz * v.y(), uy = qz * v.x() - qx * v.z(), uz = qx * v.y() - qy * v.x();
  ux += ux;
  uy += uy;
  uz += uz;
  return {v.x() + qw * ux + (qy * uz - qz * uy), v.y() + qw * uy + (qz * ux - qx * uz),
          v.z() + qw * uz + (qx * uy - qy * ux)};
}

}  // namespace

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
  Eigen::Vector3d aero_accel_W;
  if (env) {
    aero_accel_W =
        aero_force_W(params_.aero, x.q_WB.toRotationMatrix(), x.v_W, env->wind_W, omega) * reciprocals_[0];
  }
  Rigid y, r;
  pack(x, y);
  rigid_derivative(y, rigid_inputs(params_, reciprocals_, f, env ? &aero_accel_W : nullptr), r);
  d.p_W = {r[0], r[1], r[2]};
  d.v_W = {r[3], r[4], r[5]};
  d.q_WB_wxyz = {r[6], r[7], r[8], r[9]};
  d.w_B = {r[10], r[11], r[12]};
  return d;
}

Wrench Quadrotor::environment_wrench(const Vector4& omega, const State& x, const Environment& env) const {
  const Vector4 u = mixer_ * env.rotor_efficiency.cwiseProduct(omega.cwiseProduct(omega));
  return {u[0] * ground_effect_factor(params_.aero, x.p_W.z()), u.tail<3>()};
}

AppliedCommand Quadrotor::apply(const Vector4& cmd) const {
  AppliedCommand a;
  a.omega_rad_s = clamp_command(cmd);
  a.wrench = wrench(a.omega_rad_s);
  return a;
}

Outputs Quadrotor::outputs(double t_s, const State& x, const Vector4& cmd, const Environment* env) const {
  return outputs(t_s, x, apply(cmd), env);
}

Outputs Quadrotor::outputs(double t_s, const State& x, const AppliedCommand& cmd, const Environment* env) const {
  Eigen::Vector3d a_minus_g;
  if (params_.motor.model == MotorModel::kIdeal && !env) {  // derivative()'s translation only
    Rigid y;
    pack(x, y);
    bool held = false;
    a_minus_g = linear_acceleration(y, rigid_inputs(params_, reciprocals_, cmd.wrench, nullptr), held);
  } else {
    a_minus_g = derivative(t_s, x, cmd.omega_rad_s, env).v_W;
  }
  a_minus_g.z() += params_.gravity_m_s2;
  return {x.p_W, x.q_WB, x.v_W, x.w_B, rotate_by_inverse(x.q_WB, a_minus_g)};
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
    return ((a + 2.0 * b + 2.0 * c + e) * (1.0 / 6.0)).eval();
  };
  return {mix(k1.p_W, k2.p_W, k3.p_W, k4.p_W), mix(k1.v_W, k2.v_W, k3.v_W, k4.v_W),
          mix(k1.q_WB_wxyz, k2.q_WB_wxyz, k3.q_WB_wxyz, k4.q_WB_wxyz),
          mix(k1.w_B, k2.w_B, k3.w_B, k4.w_B),
          mix(k1.omega_rad_s, k2.omega_rad_s, k3.omega_rad_s, k4.omega_rad_s)};
}

}  // namespace

void Quadrotor::step(State& x, double t_s, const Vector4& cmd, double dt_s, int substeps,
                     const Environment* env) const {
  step(x, t_s, apply(cmd), dt_s, substeps, env);
}

void Quadrotor::step(State& x, double t_s, const AppliedCommand& applied, double dt_s, int substeps,
                     const Environment* env) const {
  assert(substeps >= 1);
  const Vector4& cmd = applied.omega_rad_s;
  const double h = dt_s / substeps;
  const bool ideal = params_.motor.model == MotorModel::kIdeal;
  if (ideal && !env) {
    // The rotors' wrench is the same in every stage (and was formed with the command): RK4 on 13
    // plain doubles.
    const RigidInputs in = rigid_inputs(params_, reciprocals_, applied.wrench, nullptr);
    Rigid r, k1, k2, k3, k4, y;
    pack(x, r);
    for (int s = 0; s < substeps; ++s) {
      rigid_derivative(r, in, k1);
      for (int i = 0; i < kRigid; ++i) y[i] = r[i] + (0.5 * h) * k1[i];
      rigid_derivative(y, in, k2);
      for (int i = 0; i < kRigid; ++i) y[i] = r[i] + (0.5 * h) * k2[i];
      rigid_derivative(y, in, k3);
      for (int i = 0; i < kRigid; ++i) y[i] = r[i] + h * k3[i];
      rigid_derivative(y, in, k4);
      for (int i = 0; i < kRigid; ++i) {
        r[i] = r[i] + h * ((k1[i] + 2.0 * k2[i] + 2.0 * k3[i] + k4[i]) * (1.0 / 6.0));
      }
      end_substep(r);
    }
    unpack(r, x);
    x.omega_rad_s = cmd;
    return;
  }
  for (int s = 0; s < substeps; ++s) {
    const double t = t_s + s * h;
    const StateDerivative k1 = derivative(t, x, cmd, env);
    const StateDerivative k2 = derivative(t + 0.5 * h, add_scaled(x, k1, 0.5 * h), cmd, env);
    const StateDerivative k3 = derivative(t + 0.5 * h, add_scaled(x, k2, 0.5 * h), cmd, env);
    const StateDerivative k4 = derivative(t + h, add_scaled(x, k3, h), cmd, env);
    x = add_scaled(x, weighted_sum(k1, k2, k3, k4), h);
    Rigid r;
    pack(x, r);
    end_substep(r);
    unpack(r, x);
  }
  if (ideal) {
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
