// The 6-DOF quadrotor plant as a const function dx = f(t, x, u; params), plus its fixed-step RK4
// integrator and the measured outputs. Frames: world ENU (W), body FLU (B).
#pragma once

#include <array>
#include <optional>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "model/mixer.hpp"
#include "model/vehicle_params.hpp"

namespace quadcosim::model {

/// Full plant state. Plain data: the integrator owns it, the model never stores it.
struct State {
  Eigen::Vector3d p_W = Eigen::Vector3d::Zero();             ///< position [m]
  Eigen::Vector3d v_W = Eigen::Vector3d::Zero();             ///< velocity [m/s]
  Eigen::Quaterniond q_WB = Eigen::Quaterniond::Identity();  ///< attitude, body -> world
  Eigen::Vector3d w_B = Eigen::Vector3d::Zero();             ///< body angular velocity [rad/s]
  RotorVector omega_rad_s = RotorVector::Zero(4);            ///< rotor speeds [rad/s], one per rotor
};

/// Time derivative of State; the quaternion derivative is kept as 4 raw coefficients (w, x, y, z).
struct StateDerivative {
  Eigen::Vector3d p_W;
  Eigen::Vector3d v_W;
  Eigen::Vector4d q_WB_wxyz;
  Eigen::Vector3d w_B;
  RotorVector omega_rad_s;
};

/// What the plant's sensors see at one instant (noise-free).
struct Outputs {
  Eigen::Vector3d p_W;
  Eigen::Quaterniond q_WB;
  Eigen::Vector3d v_W;
  Eigen::Vector3d w_B;
  Eigen::Vector3d specific_force_B;  ///< accelerometer reading [m/s^2]: R_BW (a_W - g_W)
};

/// Rotor speeds [rad/s] into collective thrust U1 [N] and body torques U2..U4 [N m] (eq. (4)).
struct Wrench {
  double thrust_N;
  Eigen::Vector3d torque_B_Nm;
};

/// A motor command as the model applies it: clamped (Quadrotor::clamp_command), with the rotors'
/// wrench for those speeds (eq. (4)). Formed once by Quadrotor::rotor_input and reused while the command
/// holds, so that neither step() nor outputs() forms it again on every tick.
struct RotorInput {
  RotorVector omega_rad_s = RotorVector::Zero(4);
  Wrench wrench{0.0, Eigen::Vector3d::Zero()};
};

class Quadrotor {
 public:
  explicit Quadrotor(const VehicleParams& params);

  const VehicleParams& params() const { return params_; }
  /// The 4 x N mixer (model/mixer.hpp).
  const MixerMatrix& mixer() const { return mixer_; }
  /// N, the vehicle's rotor count: every rotor vector the model takes and gives has N entries.
  int rotor_count() const { return static_cast<int>(mixer_.cols()); }

  /// Command clamped to [omega_min, omega_max]; non-finite entries become omega_min.
  RotorVector clamp_command(const RotorVector& omega_cmd_rad_s) const;

  /// Eq. (4) for the given rotor speeds.
  Wrench wrench(const RotorVector& omega_rad_s) const;

  /// The command clamped and its wrench, for the step() and outputs() overloads that take it.
  RotorInput rotor_input(const RotorVector& omega_cmd_rad_s) const;
  /// The same into `out` (a holder of the latched command: no rotor vector copied).
  void rotor_input(const RotorVector& omega_cmd_rad_s, RotorInput& out) const;

  /// dx/dt at state x under the (already clamped) commanded rotor speeds:
  ///  - translation, eq. (7) in vector form: dv_W = R_WB (0, 0, U1) / m + (0, 0, -g);
  ///  - rotation, eq. (8): dw_B = I^-1 (tau - w x I w), or eq. (11) without the gyroscopic term (I the
  ///    whole tensor when the vehicle has products of inertia, VehicleParams::inertia_tensor());
  ///  - attitude: dq = 1/2 q (0, w_B);
  ///  - rotors: ideal (derivative 0, speeds = command) or first-order lag.
  /// Ground contact: while resting on z = 0 and the forces would push it down, the ground (with
  /// friction) holds the vehicle: all accelerations are zero.
  /// With an Environment (model/aero.hpp) the rotors' thrust and drag torque are scaled by their
  /// efficiencies, the collective thrust by the ground effect, and the drag of the air moving at
  /// env->wind_W enters the translation, and with aero.rotor_aero on each rotor's drag, inflow,
  /// flapping and translational lift at its hub enter both (force and moment); without one (nullptr)
  /// the model is exactly the paper's.
  StateDerivative derivative(double t_s, const State& x, const RotorVector& omega_cmd_rad_s,
                             const Environment* env = nullptr) const;

  /// Sensor outputs at state x under the given command (the command sets the acceleration that the
  /// accelerometer measures).
  Outputs outputs(double t_s, const State& x, const RotorVector& omega_cmd_rad_s,
                  const Environment* env = nullptr) const;
  /// The same for a command already turned into its rotor input (rotor_input(omega_cmd_rad_s)): the same numbers.
  Outputs outputs(double t_s, const State& x, const RotorInput& cmd, const Environment* env = nullptr) const;

  /// Advances x by dt_s with `substeps` classical RK4 steps, command held constant. After each step
  /// the quaternion is renormalised and ground contact is enforced (z >= 0; an impact is inelastic).
  /// `env` (optional) is held constant over the step.
  void step(State& x, double t_s, const RotorVector& omega_cmd_rad_s, double dt_s, int substeps,
            const Environment* env = nullptr) const;
  /// The same for a command already turned into its rotor input (rotor_input(omega_cmd_rad_s)): the same numbers.
  void step(State& x, double t_s, const RotorInput& cmd, double dt_s, int substeps,
            const Environment* env = nullptr) const;

  /// A state at rest at p_W with rotors stopped (or at hover speed when `hover` is true).
  State initial_state(const Eigen::Vector3d& p_W, double yaw_rad, bool hover) const;

  /// What one RK4 stage's rigid-body derivative takes besides the state (defined in quadrotor.cpp).
  struct RigidInputs;

 private:
  /// RigidInputs for the rotors' wrench f, without an extra acceleration.
  RigidInputs rigid_inputs(const Wrench& f) const;
  /// The inputs at the packed state y where they vary from stage to stage (quadrotor.cpp): the
  /// rotors' wrench, eq. (4), at the command (ideal motors) or at y's rotor speeds (lag); with an
  /// Environment, each rotor's efficiency, the ground effect on U1 and the air's drag as an extra
  /// acceleration. Without either, the command's own wrench (RotorInput) is used instead.
  RigidInputs varying_inputs(const double* y, const RotorInput& cmd, const Environment* env) const;
  /// dy/dt at the packed state y; `held_inputs` are used when kVaryingInputs is false.
  template <bool kVaryingInputs, bool kRotorLag, bool kFullInertia>
  void stage_derivative(const double* y, const RotorInput& cmd, const Environment* env, const RigidInputs& held_inputs,
                        double* d) const;
  /// The rotors' wrench for the squared speeds scaled by `efficiency` (the first N entries), eq. (4):
  /// the fixed-size 4x4 product for four rotors (the paper's arithmetic), the 4 x N one otherwise.
  Eigen::Vector4d mix(const RotorVector& omega, const RotorVector* efficiency) const;
  /// The RK4 integrator of step(): `substeps` steps of h on x packed into plain doubles.
  template <bool kVaryingInputs, bool kRotorLag, bool kFullInertia>
  void integrate(State& x, const RotorInput& cmd, double h, int substeps, const Environment* env) const;
  /// The specific force at x in the world frame, a_W - g_W (Outputs::specific_force_B rotated).
  template <bool kVaryingInputs>
  Eigen::Vector3d specific_force_W(const State& x, const RotorInput& cmd, const Environment* env) const;

  VehicleParams params_;
  MixerMatrix mixer_;
  Matrix4 mixer4_;               ///< mixer_ as a fixed-size matrix when N = 4 (zero otherwise)
  Eigen::Vector4d reciprocals_;  ///< 1/m, 1/Ixx, 1/Iyy, 1/Izz: the model multiplies by them
  /// J and J^-1 row by row when the body axes are not principal axes (products of inertia); empty
  /// for the diagonal path.
  std::optional<std::array<double, 18>> full_inertia_;
  /// The hubs r_i [m] as columns, one per rotor (the per-rotor aerodynamics act there).
  Eigen::Matrix3Xd rotor_positions_B_;
};

}  // namespace quadcosim::model
