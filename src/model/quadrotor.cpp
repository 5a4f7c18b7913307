#include "model/quadrotor.hpp"

#include <algorithm>
#include <cassert>
#include <cmath>

#include <Eigen/LU>

#include "model/attitude.hpp"

namespace quadcosim::model {

Quadrotor::Quadrotor(const VehicleParams& params)
    : params_(params),
      mixer_(mixer_matrix(params)),
      mixer4_(params.rotor_count == 4 ? mixer_matrix4(params) : Matrix4::Zero()),
      reciprocals_(1.0 / params.mass_kg, 1.0 / params.Ixx_kg_m2, 1.0 / params.Iyy_kg_m2, 1.0 / params.Izz_kg_m2) {
  assert(validate(params).empty());
  rotor_positions_B_.resize(3, mixer_.cols());
  for (Eigen::Index i = 0; i < mixer_.cols(); ++i)
    rotor_positions_B_.col(i) = rotor_position_B(params, static_cast<int>(i));
  if (!params.principal_axes()) {
    using RowMajor3 = Eigen::Matrix<double, 3, 3, Eigen::RowMajor>;
    std::array<double, 18>& packed = full_inertia_.emplace();
    Eigen::Map<RowMajor3>(packed.data()) = params.inertia_tensor();
    Eigen::Map<RowMajor3>(packed.data() + 9) = params.inertia_tensor().inverse();
  }
}

RotorVector Quadrotor::clamp_command(const RotorVector& cmd) const {
  assert(cmd.size() == mixer_.cols());
  if (cmd.size() == 4) {  // the quadrotor's, unrolled
    Vector4 out;
    for (int i = 0; i < 4; ++i) {
      const double c = std::isfinite(cmd[i]) ? cmd[i] : params_.motor.omega_min_rad_s;
      out[i] = std::clamp(c, params_.motor.omega_min_rad_s, params_.motor.omega_max_rad_s);
    }
    return out;
  }
  RotorVector out(cmd.size());
  for (Eigen::Index i = 0; i < cmd.size(); ++i) {
    const double c = std::isfinite(cmd[i]) ? cmd[i] : params_.motor.omega_min_rad_s;
    out[i] = std::clamp(c, params_.motor.omega_min_rad_s, params_.motor.omega_max_rad_s);
  }
  return out;
}

Eigen::Vector4d Quadrotor::mix(const RotorVector& omega, const RotorVector* efficiency) const {
  if (mixer_.cols() == 4) {  // the fixed-size product of eq. (4), as before other rotor counts
    const Vector4 w = omega.head<4>();
    if (!efficiency) return mixer4_ * w.cwiseProduct(w);
    const Vector4 eta = efficiency->head<4>();
    return mixer4_ * eta.cwiseProduct(w.cwiseProduct(w));
  }
  const Eigen::Index n = mixer_.cols();
  if (!efficiency) return mixer_ * omega.cwiseProduct(omega);
  return mixer_ * efficiency->head(n).cwiseProduct(omega.cwiseProduct(omega));
}

Wrench Quadrotor::wrench(const RotorVector& omega) const {
  const Vector4 u = mix(omega, nullptr);
  return {u[0], u.tail<3>()};
}

namespace {

// The state as plain doubles for the integrator: the rigid body, p_W (0-2), v_W (3-5), q_WB as w, x,
// y, z (6-9), w_B (10-12), then the rotor speeds (13-13+N), which only a lagging motor integrates.
constexpr int kRigid = 13;
constexpr int kWithRotors = kRigid + kMaxRotors;
using Packed = double[kWithRotors];

inline void pack_rigid(const State& x, Packed r) {
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

/// The rotor speeds as well, where they are read: a lagging motor's state (an ideal one turns at the
/// command).
inline void pack(const State& x, bool rotor_lag, Packed r) {
  pack_rigid(x, r);
  if (rotor_lag) {
    for (Eigen::Index i = 0; i < x.omega_rad_s.size(); ++i) r[13 + i] = x.omega_rad_s[i];
  }
}

inline void unpack(const Packed r, State& x) {
  x.p_W = {r[0], r[1], r[2]};
  x.v_W = {r[3], r[4], r[5]};
  x.q_WB = Eigen::Quaterniond(r[6], r[7], r[8], r[9]);
  x.w_B = {r[10], r[11], r[12]};
}

}  // namespace

/// What the rigid body's derivative needs besides the state: the rotors' wrench (collective thrust per
/// unit mass [m/s^2], body torque [N m]), an optional extra acceleration in the world frame [m/s^2]
/// (air drag), and the vehicle's constants.
struct Quadrotor::RigidInputs {
  double thrust_per_mass;
  double torque_B[3];
  bool has_accel_W;
  double accel_W[3];
  double gravity;
  double inertia[3];
  double inv_inertia[3];
  bool gyroscopic;
  /// A vehicle whose body axes are not principal axes: J row by row (9), then J^-1 (9); nullptr for
  /// the diagonal path (inertia, inv_inertia).
  const double* full_inertia;
};

namespace {

using RigidInputs = Quadrotor::RigidInputs;

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
  if (in.has_accel_W) {  // not "+ 0.0" when there is none: that would turn a -0 into +0
    ax += in.accel_W[0];
    ay += in.accel_W[1];
    az += in.accel_W[2];
  }
  held = y[2] <= 0.0 && y[5] <= 0.0 && az <= 0.0;
  if (held) return Eigen::Vector3d::Zero();
  return {ax, ay, az};
}

/// Eq. (8) (or (11)) with the whole inertia tensor: dw = J^-1 (tau - w x J w), for a body whose axes
/// are not principal axes.
void full_angular_acceleration(const RigidInputs& in, double wx, double wy, double wz, double tau_x, double tau_y,
                               double tau_z, double& dwx, double& dwy, double& dwz) {
  const double* J = in.full_inertia;
  const double* Ji = in.full_inertia + 9;
  if (in.gyroscopic) {
    const double Iwx = J[0] * wx + J[1] * wy + J[2] * wz;
    const double Iwy = J[3] * wx + J[4] * wy + J[5] * wz;
    const double Iwz = J[6] * wx + J[7] * wy + J[8] * wz;
    tau_x -= wy * Iwz - wz * Iwy;
    tau_y -= wz * Iwx - wx * Iwz;
    tau_z -= wx * Iwy - wy * Iwx;
  }
  dwx = Ji[0] * tau_x + Ji[1] * tau_y + Ji[2] * tau_z;
  dwy = Ji[3] * tau_x + Ji[4] * tau_y + Ji[5] * tau_z;
  dwz = Ji[6] * tau_x + Ji[7] * tau_y + Ji[8] * tau_z;
}

/// The equations of Quadrotor::derivative() on the rigid body's 13 plain doubles (y -> d):
/// translation (linear_acceleration); rotation, eq. (8) (or (11)), the gyroscopic term as Eigen's
/// cross() forms it, times 1/I (a product, not a division: shorter latency on every RK4 stage), or
/// with the whole tensor (full_angular_acceleration) when there are products of inertia;
/// ground contact; dq/dt = 1/2 q (x) (0, w).
template <bool kFullInertia>
inline void rigid_derivative(const double* __restrict y, const RigidInputs& in, double* __restrict d) {
  bool held = false;
  const Eigen::Vector3d a = linear_acceleration(y, in, held);
  const double qw = y[6], qx = y[7], qy = y[8], qz = y[9];
  const double wx = y[10], wy = y[11], wz = y[12];
  double tau_x = in.torque_B[0], tau_y = in.torque_B[1], tau_z = in.torque_B[2];
  double dwx, dwy, dwz;
  if constexpr (kFullInertia) {
    full_angular_acceleration(in, wx, wy, wz, tau_x, tau_y, tau_z, dwx, dwy, dwz);
  } else {
    if (in.gyroscopic) {
      const double Iwx = in.inertia[0] * wx, Iwy = in.inertia[1] * wy, Iwz = in.inertia[2] * wz;
      tau_x -= wy * Iwz - wz * Iwy;
      tau_y -= wz * Iwx - wx * Iwz;
      tau_z -= wx * Iwy - wy * Iwx;
    }
    dwx = tau_x * in.inv_inertia[0];
    dwy = tau_y * in.inv_inertia[1];
    dwz = tau_z * in.inv_inertia[2];
  }
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

/// The end of an RK4 step: the quaternion back to unit norm; a vehicle that went below z = 0 during
/// the step touched down (inelastic impact, held by friction).
void end_substep(double* r) {
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

Quadrotor::RigidInputs Quadrotor::rigid_inputs(const Wrench& f) const {
  return {f.thrust_N * reciprocals_[0],
          {f.torque_B_Nm.x(), f.torque_B_Nm.y(), f.torque_B_Nm.z()},
          false,
          {0.0, 0.0, 0.0},
          params_.gravity_m_s2,
          {params_.Ixx_kg_m2, params_.Iyy_kg_m2, params_.Izz_kg_m2},
          {reciprocals_[1], reciprocals_[2], reciprocals_[3]},
          params_.gyroscopic == GyroscopicModel::kFull,
          full_inertia_ ? full_inertia_->data() : nullptr};
}

Quadrotor::RigidInputs Quadrotor::varying_inputs(const double* y, const RotorInput& cmd, const Environment* env) const {
  const bool ideal = params_.motor.model == MotorModel::kIdeal;
  const Eigen::Index n = mixer_.cols();
  if (!env) return rigid_inputs(ideal ? cmd.wrench : wrench(Eigen::Map<const RotorVector>(y + 13, n)));
  // The rotors turn at the command (ideal) or at the state's speeds (lag); the air's drag acts on the
  // velocity relative to the wind in the body frame.
  const RotorVector omega = ideal ? cmd.omega_rad_s : RotorVector(Eigen::Map<const RotorVector>(y + 13, n));
  const Vector4 u = mix(omega, &env->rotor_efficiency);
  RigidInputs in = rigid_inputs({u[0] * ground_effect_factor(params_.aero, y[2]), u.tail<3>()});
  const Eigen::Quaterniond q_WB(y[6], y[7], y[8], y[9]);
  const Eigen::Matrix3d R_WB = q_WB.toRotationMatrix();
  const Eigen::Vector3d v_W(y[3], y[4], y[5]);
  Eigen::Vector3d accel_W = aero_force_W(params_.aero, R_WB, v_W, env->wind_W, omega) * reciprocals_[0];
  if (params_.aero.rotor_aero_active()) {  // at the hubs: a force and a moment
    const BodyWrench w = rotor_aero_wrench_B(params_.aero, rotor_positions_B_, R_WB.transpose() * (v_W - env->wind_W),
                                             Eigen::Vector3d(y[10], y[11], y[12]), omega, env->rotor_efficiency);
    accel_W += R_WB * w.force_B * reciprocals_[0];
    for (int i = 0; i < 3; ++i) in.torque_B[i] += w.torque_B[i];
  }
  in.has_accel_W = true;
  for (int i = 0; i < 3; ++i) in.accel_W[i] = accel_W[i];
  return in;
}

template <bool kVaryingInputs, bool kRotorLag, bool kFullInertia>
void Quadrotor::stage_derivative(const double* __restrict y, const RotorInput& cmd, const Environment* env,
                                 const RigidInputs& held_inputs, double* __restrict d) const {
  if constexpr (kVaryingInputs) {
    rigid_derivative<kFullInertia>(y, varying_inputs(y, cmd, env), d);
  } else {
    rigid_derivative<kFullInertia>(y, held_inputs, d);
  }
  if constexpr (kRotorLag) {  // first-order lag towards the command, its own time constant each way
    for (Eigen::Index i = 0; i < mixer_.cols(); ++i) {
      const double err = cmd.omega_rad_s[i] - y[13 + i];
      const double tau = err > 0.0 ? params_.motor.tau_up_s : params_.motor.tau_down_s;
      d[13 + i] = err / tau;
    }
  }
}

template <bool kVaryingInputs, bool kRotorLag, bool kFullInertia>
[[gnu::always_inline]] inline void Quadrotor::integrate(State& x, const RotorInput& cmd, double h, int substeps,
                                                        const Environment* env) const {
  // Ideal rotors: their speeds are the command; lagging ones are N more states.
  const int n = kRotorLag ? kRigid + static_cast<int>(mixer_.cols()) : kRigid;
  Packed r;
  pack(x, kRotorLag, r);
  // Formed once when it is the same in every stage (ideal motors, no Environment: the paper's plant).
  const RigidInputs held_inputs = kVaryingInputs ? RigidInputs{} : rigid_inputs(cmd.wrench);
  double k1[kWithRotors], k2[kWithRotors], k3[kWithRotors], k4[kWithRotors], y[kWithRotors];
  for (int s = 0; s < substeps; ++s) {
    stage_derivative<kVaryingInputs, kRotorLag, kFullInertia>(r, cmd, env, held_inputs, k1);
    for (int i = 0; i < n; ++i) y[i] = r[i] + (0.5 * h) * k1[i];
    stage_derivative<kVaryingInputs, kRotorLag, kFullInertia>(y, cmd, env, held_inputs, k2);
    for (int i = 0; i < n; ++i) y[i] = r[i] + (0.5 * h) * k2[i];
    stage_derivative<kVaryingInputs, kRotorLag, kFullInertia>(y, cmd, env, held_inputs, k3);
    for (int i = 0; i < n; ++i) y[i] = r[i] + h * k3[i];
    stage_derivative<kVaryingInputs, kRotorLag, kFullInertia>(y, cmd, env, held_inputs, k4);
    for (int i = 0; i < n; ++i) r[i] = r[i] + h * ((k1[i] + 2.0 * k2[i] + 2.0 * k3[i] + k4[i]) * (1.0 / 6.0));
    end_substep(r);
  }
  unpack(r, x);
  if constexpr (kRotorLag) {
    x.omega_rad_s = clamp_command(Eigen::Map<const RotorVector>(r + 13, mixer_.cols()));
  } else {
    assign_rotors(x.omega_rad_s, cmd.omega_rad_s);
  }
}

StateDerivative Quadrotor::derivative(double /*t_s*/, const State& x, const RotorVector& cmd,
                                      const Environment* env) const {
  RotorInput input;
  input.omega_rad_s = cmd;  // already clamped, as the caller promises
  const bool lag = params_.motor.model == MotorModel::kFirstOrder;
  Packed y, r;
  pack(x, lag, y);
  if (!lag) {
    input.wrench = wrench(cmd);
    if (full_inertia_) {
      stage_derivative<true, false, true>(y, input, env, RigidInputs{}, r);
    } else {
      stage_derivative<true, false, false>(y, input, env, RigidInputs{}, r);
    }
    for (Eigen::Index i = 0; i < mixer_.cols(); ++i) r[13 + i] = 0.0;
  } else if (full_inertia_) {
    stage_derivative<true, true, true>(y, input, env, RigidInputs{}, r);
  } else {
    stage_derivative<true, true, false>(y, input, env, RigidInputs{}, r);
  }
  StateDerivative d;
  d.p_W = {r[0], r[1], r[2]};
  d.v_W = {r[3], r[4], r[5]};
  d.q_WB_wxyz = {r[6], r[7], r[8], r[9]};
  d.w_B = {r[10], r[11], r[12]};
  d.omega_rad_s = Eigen::Map<const RotorVector>(r + 13, mixer_.cols());
  return d;
}

RotorInput Quadrotor::rotor_input(const RotorVector& cmd) const {
  RotorInput a;
  rotor_input(cmd, a);
  return a;
}

void Quadrotor::rotor_input(const RotorVector& cmd, RotorInput& a) const {
  if (cmd.size() == 4) {  // the quadrotor's: clamp and eq. (4) on fixed-size vectors, as before other counts
    Vector4 w;
    for (int i = 0; i < 4; ++i) {
      const double c = std::isfinite(cmd[i]) ? cmd[i] : params_.motor.omega_min_rad_s;
      w[i] = std::clamp(c, params_.motor.omega_min_rad_s, params_.motor.omega_max_rad_s);
    }
    a.omega_rad_s.resize(4);
    a.omega_rad_s.head<4>() = w;
    const Vector4 u = mixer4_ * w.cwiseProduct(w);
    a.wrench = {u[0], u.tail<3>()};
    return;
  }
  a.omega_rad_s = clamp_command(cmd);
  a.wrench = wrench(a.omega_rad_s);
}

Outputs Quadrotor::outputs(double t_s, const State& x, const RotorVector& cmd, const Environment* env) const {
  return outputs(t_s, x, rotor_input(cmd), env);
}

template <bool kVaryingInputs>
[[gnu::always_inline]] inline Eigen::Vector3d Quadrotor::specific_force_W(const State& x, const RotorInput& cmd,
                                                                          const Environment* env) const {
  Packed y;
  pack(x, params_.motor.model == MotorModel::kFirstOrder, y);
  bool held = false;
  // derivative()'s translation only, with the inputs of a step's first stage.
  Eigen::Vector3d a_minus_g =
      linear_acceleration(y, kVaryingInputs ? varying_inputs(y, cmd, env) : rigid_inputs(cmd.wrench), held);
  a_minus_g.z() += params_.gravity_m_s2;
  return a_minus_g;
}

Outputs Quadrotor::outputs(double /*t_s*/, const State& x, const RotorInput& cmd, const Environment* env) const {
  // As step(), compiled for what varies: nothing but the state for ideal motors without an Environment.
  const bool varying = env || params_.motor.model == MotorModel::kFirstOrder;
  const Eigen::Vector3d a_minus_g_W =
      varying ? specific_force_W<true>(x, cmd, env) : specific_force_W<false>(x, cmd, env);
  return {x.p_W, x.q_WB, x.v_W, x.w_B, rotate_by_inverse(x.q_WB, a_minus_g_W)};
}

void Quadrotor::step(State& x, double t_s, const RotorVector& cmd, double dt_s, int substeps,
                     const Environment* env) const {
  step(x, t_s, rotor_input(cmd), dt_s, substeps, env);
}

void Quadrotor::step(State& x, double /*t_s*/, const RotorInput& input, double dt_s, int substeps,
                     const Environment* env) const {
  assert(substeps >= 1);
  const double h = dt_s / substeps;
  // One integrator, compiled for what varies over a step's stages: nothing for ideal motors without
  // an Environment (the rotors' wrench was formed with the command), the wrench and drag at each
  // stage's state otherwise, and the rotor speeds too for a lagging motor.
  // A body with products of inertia takes the whole tensor (a path of its own, so that the paper's
  // diagonal one is compiled as before).
  const bool lag = params_.motor.model == MotorModel::kFirstOrder;
  if (full_inertia_) {
    if (lag) {
      integrate<true, true, true>(x, input, h, substeps, env);
    } else {
      integrate<true, false, true>(x, input, h, substeps, env);
    }
  } else if (lag) {
    integrate<true, true, false>(x, input, h, substeps, env);
  } else if (env) {
    integrate<true, false, false>(x, input, h, substeps, env);
  } else {
    integrate<false, false, false>(x, input, h, substeps, nullptr);
  }
}

State Quadrotor::initial_state(const Eigen::Vector3d& p_W, double yaw_rad, bool hover) const {
  State x;
  x.omega_rad_s = RotorVector::Zero(mixer_.cols());
  x.p_W = p_W;
  x.q_WB = quaternion_from_euler({0.0, 0.0, yaw_rad});
  if (hover) x.omega_rad_s.setConstant(params_.hover_omega_rad_s());
  return x;
}

}  // namespace quadcosim::model
