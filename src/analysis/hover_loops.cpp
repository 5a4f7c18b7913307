#include "analysis/hover_loops.hpp"

#include <Eigen/LU>
#include <algorithm>
#include <cmath>
#include <sstream>
#include <stdexcept>

#include "model/mixer.hpp"

namespace quadcosim::analysis {

namespace {

using Eigen::MatrixXd;
using Eigen::RowVectorXd;

// A continuous channel model: dx/dt = A x + B u, measured outputs C x, each with the latency of the
// sensor that carries it.
struct Channel {
  MatrixXd A, B, C;
  std::vector<int> latency_ticks;
};

// The discrete (or continuous) plant of a channel as the controller sees it.
StateSpace plant_of(const Channel& ch, const LoopTiming& t) {
  if (t.continuous) {
    StateSpace s{ch.A, ch.B, ch.C, MatrixXd::Zero(ch.C.rows(), 1), 0.0};
    return s;
  }
  SampledPlantSpec spec;
  spec.A = ch.A;
  spec.B = ch.B;
  spec.C = ch.C;
  spec.tick_s = t.tick_s;
  spec.ticks_per_sample = t.controller_divider;
  spec.input_delay_ticks = t.command_delay_ticks;
  spec.output_delay_ticks = ch.latency_ticks;
  return sample_plant(spec);
}

StateSpace static_controller(const RowVectorXd& gains, const LoopTiming& t) {
  StateSpace s;
  s.A = MatrixXd::Zero(0, 0);
  s.B = MatrixXd::Zero(0, gains.size());
  s.C = MatrixXd::Zero(1, 0);
  s.D = gains;
  s.period_s = t.continuous ? 0.0 : t.tick_s * t.controller_divider;
  return s;
}

// Rotational channel of one axis: [angle, rate] (+ [torque] with motor lag), input the torque
// demand scaled by the allocation's gain on it.
Channel attitude_channel(double inertia, double gain, double tau_motor, int imu_latency) {
  Channel ch;
  if (tau_motor > 0.0) {
    ch.A = MatrixXd::Zero(3, 3);
    ch.A(0, 1) = 1.0;
    ch.A(1, 2) = 1.0 / inertia;
    ch.A(2, 2) = -1.0 / tau_motor;
    ch.B = MatrixXd::Zero(3, 1);
    ch.B(2, 0) = gain / tau_motor;
  } else {
    ch.A = MatrixXd::Zero(2, 2);
    ch.A(0, 1) = 1.0;
    ch.B = MatrixXd::Zero(2, 1);
    ch.B(1, 0) = gain / inertia;
  }
  ch.C = MatrixXd::Identity(2, ch.A.rows());
  ch.latency_ticks = {imu_latency, imu_latency};
  return ch;
}

// Vertical channel: [z, vz] (+ [thrust] with motor lag), linear drag d [N s/m].
Channel altitude_channel(double mass, double drag, double gain, double tau_motor, const LoopTiming& t) {
  Channel ch;
  const int n = tau_motor > 0.0 ? 3 : 2;
  ch.A = MatrixXd::Zero(n, n);
  ch.B = MatrixXd::Zero(n, 1);
  ch.A(0, 1) = 1.0;
  ch.A(1, 1) = -drag / mass;
  if (tau_motor > 0.0) {
    ch.A(1, 2) = 1.0 / mass;
    ch.A(2, 2) = -1.0 / tau_motor;
    ch.B(2, 0) = gain / tau_motor;
  } else {
    ch.B(1, 0) = gain / mass;
  }
  ch.C = MatrixXd::Identity(2, n);
  ch.latency_ticks = {t.pose_latency_ticks, t.velocity_latency_ticks};
  return ch;
}

// Horizontal channel through one tilt axis, heading frame: [p, v, angle, rate] (+ [torque]),
// dv/dt = sign g angle - (drag / m) v. sign +1: x through pitch; -1: y through roll.
Channel horizontal_channel(double mass, double g, double drag, double inertia, double gain, double tau_motor,
                           double sign, const LoopTiming& t) {
  const Channel rot = attitude_channel(inertia, gain, tau_motor, t.imu_latency_ticks);
  const int r = static_cast<int>(rot.A.rows());
  Channel ch;
  ch.A = MatrixXd::Zero(2 + r, 2 + r);
  ch.A(0, 1) = 1.0;
  ch.A(1, 1) = -drag / mass;
  ch.A(1, 2) = sign * g;
  ch.A.bottomRightCorner(r, r) = rot.A;
  ch.B = MatrixXd::Zero(2 + r, 1);
  ch.B.bottomRows(r) = rot.B;
  ch.C = MatrixXd::Identity(4, 2 + r);
  ch.latency_ticks = {t.pose_latency_ticks, t.velocity_latency_ticks, t.imu_latency_ticks, t.imu_latency_ticks};
  return ch;
}

// The position PID of one heading-frame axis as a map from [p, v, angle, rate] to the tilt setpoint:
// a = kp e + ki int(e) - kd v with e = -p, tilt = sign a / g. The integral I_k = I_(k-1) + T e_k is
// used after its update (control/position_pid.cpp); without ki there is no integrator state.
StateSpace position_controller(const control::PositionGains& k, double g, double sign, const LoopTiming& t) {
  const double T = t.continuous ? 0.0 : t.tick_s * t.controller_divider;
  StateSpace s;
  s.period_s = T;
  s.D = RowVectorXd::Zero(4);
  s.D(0) = sign * (-k.kp - k.ki * T) / g;
  s.D(1) = sign * (-k.kd) / g;
  if (k.ki != 0.0) {
    s.A = MatrixXd::Constant(1, 1, t.continuous ? 0.0 : 1.0);
    s.B = MatrixXd::Zero(1, 4);
    s.B(0, 0) = t.continuous ? -1.0 : -T;
    s.C = MatrixXd::Constant(1, 1, sign * k.ki / g);
  } else {
    s.A = MatrixXd::Zero(0, 0);
    s.B = MatrixXd::Zero(0, 4);
    s.C = MatrixXd::Zero(1, 0);
  }
  return s;
}

// u = inner y + outer_gain * w(y): the torque from the attitude law fed by the position PID.
StateSpace compose(const RowVectorXd& inner, double outer_gain, const StateSpace& w) {
  StateSpace s = w;
  s.C = outer_gain * w.C;
  s.D = inner + outer_gain * w.D;
  return s;
}

}  // namespace

std::string hover_trim_problem(const model::VehicleParams& p) {
  if (std::string why = model::validate(p); !why.empty()) return "the vehicle is not valid: " + why;
  const double w = p.hover_omega_rad_s();
  std::ostringstream s;
  if (!(w < p.motor.omega_max_rad_s)) {
    s << "the vehicle cannot hover: each rotor would need " << w
      << " rad/s, not below motor.omega_max_rad_s = " << p.motor.omega_max_rad_s;
  } else if (!(w > p.motor.omega_min_rad_s)) {
    s << "the vehicle cannot hover: each rotor would need " << w
      << " rad/s, not above motor.omega_min_rad_s = " << p.motor.omega_min_rad_s;
  }
  return s.str();
}

std::vector<HoverLoop> hover_loops(const model::VehicleParams& plant, const controllers::PaperController& fc,
                                   control::Mode mode, const LoopTiming& t) {
  if (const std::string why = hover_trim_problem(plant); !why.empty()) throw std::invalid_argument(why);
  if (!t.continuous && (!(t.tick_s > 0.0) || t.controller_divider < 1 || t.command_delay_ticks < 0 ||
                        t.imu_latency_ticks < 0 || t.pose_latency_ticks < 0 || t.velocity_latency_ticks < 0))
    throw std::invalid_argument("loop timing: tick must be > 0, divider >= 1 and latencies >= 0");
  const controllers::PaperParams& params = fc.params();

  // The allocation hands the plant Omega^2 = M_c^-1 U (thrust is k_t omega^2), so the plant's
  // generalised input is M_p M_c^-1 U: the identity when controller and plant agree on the vehicle.
  const Eigen::Matrix4d alloc = model::mixer_matrix4(plant) * model::mixer_matrix4(fc.vehicle()).inverse();
  const double tau = plant.motor.model == model::MotorModel::kFirstOrder
                         ? std::max(plant.motor.tau_up_s, plant.motor.tau_down_s)
                         : 0.0;
  const double inertia[3] = {plant.Ixx_kg_m2, plant.Iyy_kg_m2, plant.Izz_kg_m2};
  const char* names[3] = {"roll", "pitch", "yaw"};
  const char* breaks[3] = {"U2 roll torque [N m]", "U3 pitch torque [N m]", "U4 yaw torque [N m]"};
  const double g_c = fc.vehicle().gravity_m_s2;
  // In-plane drag at hover: linear body drag plus rotor drag k_rd * sum(omega) = 4 omega_h k_rd.
  const double rotor_drag = 4.0 * plant.hover_omega_rad_s() * plant.aero.rotor_drag_N_s_m_per_rad_s;

  std::vector<HoverLoop> loops;
  for (int i = 0; i < 3; ++i) {
    const control::AxisLqr& ax = fc.axis(i);
    // torque = -(K0 e + K1 rate), e = des - angle: per measured [angle, rate], [K0, -K1].
    RowVectorXd att(2);
    att << ax.K(0), -ax.K(1);
    const bool horizontal = mode == control::Mode::kPosition && i < 2;
    if (!horizontal) {
      const Channel ch = attitude_channel(inertia[i], alloc(i + 1, i + 1), tau, t.imu_latency_ticks);
      loops.push_back({names[i], breaks[i], {plant_of(ch, t), static_controller(att, t)}});
      continue;
    }
    const double sign = i == 1 ? 1.0 : -1.0;  // x through pitch (+g theta), y through roll (-g phi)
    const Channel ch =
        horizontal_channel(plant.mass_kg, plant.gravity_m_s2, plant.aero.linear_drag_N_s_m[i == 1 ? 0 : 1] + rotor_drag,
                           inertia[i], alloc(i + 1, i + 1), tau, sign, t);
    RowVectorXd inner = RowVectorXd::Zero(4);
    inner(2) = att(0);
    inner(3) = att(1);
    const StateSpace pid = position_controller(params.position, g_c, sign, t);
    // At the torque: torque = K0 (angle - tilt_des) - K1 rate, tilt_des from the PID.
    loops.push_back({names[i], breaks[i], {plant_of(ch, t), compose(inner, -ax.K(0), pid)}});
  }

  const Channel alt = altitude_channel(plant.mass_kg, plant.aero.linear_drag_N_s_m[2], alloc(0, 0), tau, t);
  RowVectorXd pd(2);
  pd << -params.altitude.kp, -params.altitude.kd;
  loops.push_back({"altitude", "U1 collective thrust [N]", {plant_of(alt, t), static_controller(pd, t)}});

  if (mode == control::Mode::kPosition) {
    // Broken at the tilt setpoint: the plant is the vehicle with its attitude loop closed.
    for (int i : {1, 0}) {
      const HoverLoop& at_torque = loops[static_cast<std::size_t>(i)];
      const control::AxisLqr& ax = fc.axis(i);
      const double sign = i == 1 ? 1.0 : -1.0;
      RowVectorXd inner = RowVectorXd::Zero(4);
      inner(2) = ax.K(0);
      inner(3) = -ax.K(1);
      StateSpace closed = at_torque.loop.plant;
      closed.A = closed.A + closed.B * inner * closed.C;
      closed.B = closed.B * (-ax.K(0));
      loops.push_back({i == 1 ? "position_x" : "position_y",
                       i == 1 ? "pitch_des tilt setpoint [rad]" : "roll_des tilt setpoint [rad]",
                       {closed, position_controller(params.position, g_c, sign, t)}});
    }
  }
  return loops;
}

}  // namespace quadcosim::analysis
