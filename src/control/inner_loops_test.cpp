// The inner loops of the command levels (control/inner_loops.hpp) against formulas of their own: the
// rate loop's first-order response, the attitude loop's second-order one, hover, the velocity loop's
// time constant, the thrust and torque levels through the rotor equations, saturation and bad input.
#include "control/inner_loops.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <string>

#include "control/command_level.hpp"
#include "model/attitude.hpp"
#include "model/mixer.hpp"
#include "model/quadrotor.hpp"
#include "model/vehicle_presets.hpp"

namespace quadcosim::control {
namespace {

constexpr double kPeriod = 0.01;  // the paper's 100 Hz plant

/// Flies `sp` from `x` for `ticks` plant ticks as the plant does: the loops on the true state, their
/// rotor speeds held over the tick, one RK4 step of the period. Calls f(k, state at t_k).
template <class F>
model::State fly(const model::VehicleParams& vehicle, const InnerLoops& loops, const LevelCommand& sp, model::State x,
                 int ticks, F f) {
  const model::Quadrotor quad(vehicle);
  for (int k = 0; k < ticks; ++k) {
    f(k, x);
    const InnerLoopOutput out = loops.step(sp, x);
    quad.step(x, k * kPeriod, out.allocation.omega_rad_s, kPeriod, 1);
  }
  f(ticks, x);
  return x;
}

model::State hovering(const model::VehicleParams& v, double z = 10.0) {
  return model::Quadrotor(v).initial_state({0.0, 0.0, z}, 0.0, true);
}

TEST(CommandLevel, NamesRoundTripAndUnknownNamesAreRefusedWithTheList) {
  for (std::string_view name : command_level_names()) {
    ASSERT_TRUE(command_level_from_string(name).has_value()) << name;
    EXPECT_EQ(to_string(*command_level_from_string(name)), name);
  }
  EXPECT_FALSE(command_level_from_string("ctrb").has_value());
  const std::string err = unknown_command_level("ctrb");
  EXPECT_NE(err.find("unknown command level 'ctrb'"), std::string::npos) << err;
  EXPECT_NE(err.find("rotor_speeds, rotor_thrusts, ctbr, ctatt, cttm, velocity, acceleration"), std::string::npos);
  EXPECT_NE(err.find("did you mean 'ctbr'"), std::string::npos) << err;
}

TEST(CommandLevel, BadSetpointsAreRefusedNamingTheValue) {
  const double nan = std::nan("");
  const double good[4] = {19.0, 0.0, 0.0, 0.0};
  EXPECT_EQ(check_setpoint(CommandLevel::kCtbr, good, 4), "");
  EXPECT_EQ(check_setpoint(CommandLevel::kCtbr, good, 3), "ctbr: expected 4 values, got 3");
  const double bad[4] = {19.0, 0.0, nan, 0.0};
  EXPECT_EQ(check_setpoint(CommandLevel::kCtbr, bad, 4), "ctbr: value 3 (q [rad/s]) is nan, expected a finite number");
  const double inf[4] = {1.0, 1.0, 1.0, INFINITY};
  EXPECT_EQ(check_setpoint(CommandLevel::kVelocity, inf, 4),
            "velocity: value 4 (yaw [rad]) is inf, expected a finite number");
  const double negative[4] = {1.0, -0.5, 1.0, 1.0};
  EXPECT_EQ(check_setpoint(CommandLevel::kRotorThrusts, negative, 4), "");  // clamped by the loops, flagged
  // Torques and rates may be negative.
  const double signs[4] = {1.0, -0.5, -1.0, -1.0};
  EXPECT_EQ(check_setpoint(CommandLevel::kCttm, signs, 4), "");
}

TEST(InnerLoops, RateStepOnOneAxisIsFirstOrderWithTimeConstantOneOverKw) {
  // J dw/dt = M - w x J w with M = J K' (w_des - w) + w x J w is dw/dt = K' (w_des - w). The moment is
  // held over each tick (ideal motors), so w_{k+1} - w_des = (1 - K' h)(w_k - w_des) = exp(-K_w h)(...)
  // with the pole-matched K' = (1 - exp(-K_w h)) / h: at the ticks w(t) = w_des (1 - exp(-K_w t)) up to
  // rounding. Only the roll axis moves (the other rates stay 0, so w x J w = 0).
  const model::VehicleParams v;
  const InnerLoops loops(v, {}, kPeriod);
  const double kw = loops.params().rate_bandwidth_rad_s;
  ASSERT_EQ(kw, 30.0);
  const double w_des = 0.5;
  const LevelCommand sp{CommandLevel::kCtbr, {v.mass_kg * v.gravity_m_s2, w_des, 0.0, 0.0}};
  double worst = 0.0, worst_other = 0.0;
  fly(v, loops, sp, hovering(v), 50, [&](int k, const model::State& x) {
    const double expected = w_des * (1.0 - std::exp(-kw * k * kPeriod));
    worst = std::max(worst, std::abs(x.w_B.x() - expected));
    worst_other = std::max(worst_other, std::max(std::abs(x.w_B.y()), std::abs(x.w_B.z())));
  });
  EXPECT_LT(worst, 1e-12);
  EXPECT_LT(worst_other, 1e-12);
  // The same for every preset and every axis (their own inertia tensors, the gains scaled by them).
  for (const model::VehiclePreset& preset : model::vehicle_presets()) {
    model::VehicleParams pv = preset.params;
    pv.motor.model = model::MotorModel::kIdeal;
    pv.Ixy_kg_m2 = pv.Ixz_kg_m2 = pv.Iyz_kg_m2 = 0.0;
    const InnerLoops pl(pv, {}, kPeriod);
    for (int axis = 0; axis < 3; ++axis) {
      LevelCommand s{CommandLevel::kCtbr, {pv.mass_kg * pv.gravity_m_s2, 0.0, 0.0, 0.0}};
      // Small enough that no rotor saturates (yaw's drag torque is the weakest: 0.005 rad/s).
      const double step = axis == 2 ? 0.005 : 0.2;
      s.value[1 + axis] = step;
      double err = 0.0;
      fly(pv, pl, s, hovering(pv), 30, [&](int k, const model::State& x) {
        err = std::max(err, std::abs(x.w_B[axis] - step * (1.0 - std::exp(-30.0 * k * kPeriod))));
        EXPECT_FALSE(pl.step(s, x).saturated()) << preset.name << " axis " << axis << " tick " << k;
      });
      EXPECT_LT(err, 1e-12 * 1e3 * step) << preset.name << " axis " << axis;
    }
  }
}

TEST(InnerLoops, AttitudeStepSettlesAsTheCascadesSecondOrderResponse) {
  // Small angles, the rate loop a first-order lag: e'' + K_w e' + K_w K_R e = 0. At the defaults
  // (K_w = 4 K_R) a double pole at -K_w / 2: e(t) = e0 (1 + K_w t / 2) exp(-K_w t / 2). The loops are
  // sampled at 100 Hz (K_w h = 0.3): the simulated error stays within 3 % of the step of this
  // continuous solution (measured 1.7 %; 1.0 % after 0.4 s), and settles below 2 % of the step by 6 / (K_w/2) = 0.4 s.
  const model::VehicleParams v;
  const InnerLoops loops(v, {}, kPeriod);
  const double lambda = loops.params().rate_bandwidth_rad_s / 2.0;
  const double step = 0.05;
  const LevelCommand sp{CommandLevel::kCtatt, {v.mass_kg * v.gravity_m_s2, step, 0.0, 0.0}};
  double worst = 0.0, after = 0.0;
  fly(v, loops, sp, hovering(v), 100, [&](int k, const model::State& x) {
    const double t = k * kPeriod;
    const double e = model::euler_from_quaternion(x.q_WB).roll_rad - step;
    const double expected = -step * (1.0 + lambda * t) * std::exp(-lambda * t);
    worst = std::max(worst, std::abs(e - expected));
    if (t >= 6.0 / lambda) after = std::max(after, std::abs(e));
  });
  EXPECT_LT(worst, 0.03 * step);
  EXPECT_LT(after, 0.02 * step);
}

TEST(InnerLoops, CtbrHoverHoldsAltitude) {
  // Thrust m g, zero rates, from hover: the allocation gives sum k_t omega^2 = m g, the rates stay 0.
  for (const model::VehiclePreset& preset : model::vehicle_presets()) {
    const model::VehicleParams& v = preset.params;
    const InnerLoops loops(v, {}, kPeriod);
    const LevelCommand sp{CommandLevel::kCtbr, {v.mass_kg * v.gravity_m_s2, 0.0, 0.0, 0.0}};
    const model::State end = fly(v, loops, sp, hovering(v, 5.0), 1000, [](int, const model::State&) {});
    EXPECT_NEAR(end.p_W.z(), 5.0, 1e-6) << preset.name;
    EXPECT_LT(end.w_B.norm(), 1e-9) << preset.name;
  }
}

TEST(InnerLoops, VelocityLevelReachesTheCommandWithTheStatedTimeConstant) {
  // Vertical: level, U1 = m (g + K' (v_des - v)) along z: the pole-matched first order, exact at the
  // ticks, v_z(t) = v_des (1 - exp(-K_v t)).
  const model::VehicleParams v;
  const InnerLoops loops(v, {}, kPeriod);
  const double kv = loops.params().velocity_bandwidth_rad_s;
  double worst = 0.0;
  fly(v, loops, {CommandLevel::kVelocity, {0.0, 0.0, 1.0, 0.0}}, hovering(v), 300, [&](int k, const model::State& x) {
    worst = std::max(worst, std::abs(x.v_W.z() - (1.0 - std::exp(-kv * k * kPeriod))));
  });
  EXPECT_LT(worst, 1e-9);
  // Horizontal: the vehicle must tilt first (attitude loop, about 2/lambda = 0.13 s), then the same
  // first order: by t = 1/K_v + 0.2 s at least 1 - exp(-1) of the way; within 2 % after 5/K_v + 0.2 s;
  // overshoot under 5 %. Every preset.
  for (const model::VehiclePreset& preset : model::vehicle_presets()) {
    const model::VehicleParams& pv = preset.params;
    const InnerLoops pl(pv, {}, kPeriod);
    double at_tau = 0.0, late = 0.0, peak = 0.0;
    fly(pv, pl, {CommandLevel::kVelocity, {1.0, 0.0, 0.0, 0.0}}, hovering(pv), 600, [&](int k, const model::State& x) {
      const double t = k * kPeriod;
      if (k == static_cast<int>(std::lround((1.0 / kv + 0.2) / kPeriod))) at_tau = x.v_W.x();
      if (t >= 5.0 / kv + 0.2) late = std::max(late, std::abs(x.v_W.x() - 1.0));
      peak = std::max(peak, x.v_W.x());
    });
    EXPECT_GT(at_tau, 1.0 - std::exp(-1.0)) << preset.name;
    EXPECT_LT(late, 0.02) << preset.name;
    EXPECT_LT(peak, 1.05) << preset.name;
  }
}

TEST(InnerLoops, RotorThrustsAreSquareRootsOfThrustOverKt) {
  const model::VehicleParams v;
  const InnerLoops loops(v, {}, kPeriod);
  const Eigen::Vector4d T(1.0, 2.5, 4.0, 7.25);
  const InnerLoopOutput out = loops.step({CommandLevel::kRotorThrusts, T}, hovering(v));
  for (int i = 0; i < 4; ++i) {
    EXPECT_EQ(out.allocation.omega_rad_s[i], std::sqrt(T[i] / 2.06e-7)) << i;
    EXPECT_FALSE(out.allocation.saturated[i]);
  }
  // Above omega_max^2 k_t = 29.664 N: clamped to 12000 rad/s and flagged.
  const InnerLoopOutput high = loops.step({CommandLevel::kRotorThrusts, {1.0, 40.0, 1.0, 1.0}}, hovering(v));
  EXPECT_EQ(high.allocation.omega_rad_s[1], 12000.0);
  EXPECT_TRUE(high.allocation.saturated[1]);
  EXPECT_TRUE(high.saturated());
}

TEST(InnerLoops, CttmMakesTheRequestedWrenchThroughTheMixer) {
  // eq. (4) for the paper's '+' layout by hand: U1 = k_t sum w^2, U2 = L k_t (w4^2 - w2^2),
  // U3 = L k_t (w3^2 - w1^2), U4 = k_m (-w1^2 + w2^2 - w3^2 + w4^2) (spin signs of model::mixer_matrix).
  const model::VehicleParams v;
  const InnerLoops loops(v, {}, kPeriod);
  const Eigen::Vector4d U(25.0, 0.3, -0.2, 0.01);
  const InnerLoopOutput out = loops.step({CommandLevel::kCttm, U}, hovering(v));
  EXPECT_FALSE(out.saturated());
  const Eigen::Vector4d w2 = out.allocation.omega_rad_s.cwiseAbs2();
  const Eigen::Vector4d made = model::mixer_matrix(v) * w2;
  for (int i = 0; i < 4; ++i) EXPECT_NEAR(made[i], U[i], 1e-12 * std::max(1.0, std::abs(U[i]))) << i;
  EXPECT_NEAR(v.kt_N_per_rad2_s2 * w2.sum(), 25.0, 1e-11);
  EXPECT_EQ(out.U, U);
  // A torque the rotors cannot make: clamped into [omega_min, omega_max] and flagged.
  const InnerLoopOutput sat = loops.step({CommandLevel::kCttm, {25.0, 50.0, 0.0, 0.0}}, hovering(v));
  EXPECT_TRUE(sat.saturated());
  for (int i = 0; i < 4; ++i) {
    EXPECT_GE(sat.allocation.omega_rad_s[i], 0.0);
    EXPECT_LE(sat.allocation.omega_rad_s[i], 12000.0);
  }
}

TEST(InnerLoops, AnAccelerationBeyondTheTiltLimitIsCutAndFlagged) {
  const model::VehicleParams v;
  const InnerLoops loops(v, {}, kPeriod);
  const InnerLoops::ThrustAttitude ta = loops.thrust_attitude({30.0, 0.0, 0.0}, 0.0, Eigen::Matrix3d::Identity());
  EXPECT_TRUE(ta.tilt_saturated);
  EXPECT_NEAR(std::acos(ta.R_des(2, 2)), 0.7, 1e-12);           // the tilt of b3 is the limit
  EXPECT_NEAR(ta.thrust_N, v.mass_kg * v.gravity_m_s2, 1e-12);  // the vertical part kept (level vehicle)
  const InnerLoopOutput out = loops.step({CommandLevel::kAcceleration, {30.0, 0.0, 0.0, 0.0}}, hovering(v));
  EXPECT_TRUE(out.tilt_saturated);
  // Within the limit: b3 along (a + g e3), no flag.
  const InnerLoops::ThrustAttitude ok = loops.thrust_attitude({1.0, 0.0, 0.0}, 0.0, Eigen::Matrix3d::Identity());
  EXPECT_FALSE(ok.tilt_saturated);
  EXPECT_NEAR(std::atan2(ok.R_des(0, 2), ok.R_des(2, 2)), std::atan2(1.0, 9.81), 1e-12);
}

TEST(InnerLoops, GainsTheSampledLoopCannotHoldAreRefusedByName) {
  const model::VehicleParams v;
  EXPECT_EQ(check_inner_loops({}, v, kPeriod), "");
  for (const model::VehiclePreset& preset : model::vehicle_presets()) {
    EXPECT_EQ(check_inner_loops({}, preset.params, kPeriod), "") << preset.name;
  }
  InnerLoopParams p;
  p.rate_bandwidth_rad_s = 150.0;
  EXPECT_EQ(check_inner_loops(p, v, kPeriod),
            "inner.rate_bandwidth 150 rad/s is too fast for the plant period 0.01 s: K_w * period must be <= 1 (at "
            "most 100 rad/s)");
  EXPECT_THROW(InnerLoops(v, p, kPeriod), std::invalid_argument);
  p = {};
  p.attitude_bandwidth_rad_s = 300.0;
  EXPECT_EQ(check_inner_loops(p, v, kPeriod).rfind("inner.attitude_bandwidth 300 rad/s is unstable", 0), 0u)
      << check_inner_loops(p, v, kPeriod);
  p = {};
  p.velocity_bandwidth_rad_s = 200.0;
  EXPECT_EQ(check_inner_loops(p, v, kPeriod).rfind("inner.velocity_bandwidth 200 rad/s is unstable", 0), 0u)
      << check_inner_loops(p, v, kPeriod);
  // A first-order motor of 0.04 s: K_w tau <= 1 allows 25 rad/s.
  model::VehicleParams lag = v;
  lag.motor.model = model::MotorModel::kFirstOrder;
  EXPECT_EQ(check_inner_loops({}, lag, kPeriod).rfind("inner.rate_bandwidth 30 rad/s is too fast for the motors'", 0),
            0u);
  // The defaults designed for a vehicle fit it: the paper's at 100 Hz are the struct's; a 0.04 s motor
  // gets K_w = 0.75 / 0.04 = 18.75 rad/s; a 50 Hz plant K_w = 0.3 / 0.02 = 15 rad/s.
  const InnerLoopParams d = InnerLoopParams::for_vehicle(v, kPeriod);
  EXPECT_EQ(d.rate_bandwidth_rad_s, 30.0);
  EXPECT_EQ(d.attitude_bandwidth_rad_s, 7.5);
  EXPECT_EQ(d.velocity_bandwidth_rad_s, 1.5);
  EXPECT_EQ(InnerLoopParams::for_vehicle(lag, kPeriod).rate_bandwidth_rad_s, 18.75);
  EXPECT_EQ(check_inner_loops(InnerLoopParams::for_vehicle(lag, kPeriod), lag, kPeriod), "");
  EXPECT_DOUBLE_EQ(InnerLoopParams::for_vehicle(v, 0.02).rate_bandwidth_rad_s, 15.0);
  for (const model::VehiclePreset& preset : model::vehicle_presets()) {
    for (double h : {0.001, 0.004, 0.01, 0.02, 0.05}) {
      EXPECT_EQ(check_inner_loops(InnerLoopParams::for_vehicle(preset.params, h), preset.params, h), "")
          << preset.name << " " << h;
    }
  }
  // The table's names and ranges.
  InnerLoopParams q;
  EXPECT_EQ(inner_loop_table().set(q, "inner.rate_bandwidth", 20.0), "");
  EXPECT_EQ(q.rate_bandwidth_rad_s, 20.0);
  EXPECT_NE(inner_loop_table().set(q, "inner.rate_bandwith", 20.0).find("did you mean 'inner.rate_bandwidth'"),
            std::string::npos);
}

}  // namespace
}  // namespace quadcosim::control
