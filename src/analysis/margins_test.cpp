// Loop margins against closed forms (continuous and sampled), how they move with delay and
// controller rate, and the linearised loops against the LQR design and the nonlinear simulation.
#include <gtest/gtest.h>

#include <cmath>
#include <memory>
#include <numbers>

#include "analysis/hover_loops.hpp"
#include "analysis/margins.hpp"
#include "controllers/paper/paper_controller.hpp"
#include "controllers/registry.hpp"
#include "model/attitude.hpp"
#include "sim/simulation.hpp"

namespace quadcosim::analysis {
namespace {

constexpr double kPi = std::numbers::pi;
using Eigen::MatrixXd;
using Eigen::RowVectorXd;

StateSpace gains(const RowVectorXd& k, double period_s) {
  return {MatrixXd::Zero(0, 0), MatrixXd::Zero(0, k.size()), MatrixXd::Zero(1, 0), k, period_s};
}

// 1/(J s^2) with outputs [x, v].
SampledPlantSpec double_integrator(double J, double tick_s, int ticks_per_sample, int delay_ticks = 0) {
  SampledPlantSpec s;
  s.A = MatrixXd::Zero(2, 2);
  s.A(0, 1) = 1.0;
  s.B = MatrixXd::Zero(2, 1);
  s.B(1, 0) = 1.0 / J;
  s.C = MatrixXd::Identity(2, 2);
  s.tick_s = tick_s;
  s.ticks_per_sample = ticks_per_sample;
  s.input_delay_ticks = delay_ticks;
  return s;
}

// PD u = -(kp x + kd v) around a double integrator, sampled at N ticks of `tick` (delay in ticks).
Loop pd_loop(double J, double kp, double kd, double tick, int N, int delay_ticks = 0) {
  RowVectorXd k(2);
  k << -kp, -kd;
  return {sample_plant(double_integrator(J, tick, N, delay_ticks)), gains(k, tick * N)};
}

TEST(MarginsTest, ContinuousDoubleIntegratorUnderPdMatchesTheClosedForm) {
  // L(s) = (kd s + kp) / (J s^2): |L| = 1 at w^2 = (kd^2 + sqrt(kd^4 + 4 J^2 kp^2)) / (2 J^2),
  // PM = atan(kd w / kp), no phase crossover (the phase never reaches -180 deg): GM infinite.
  const double J = 0.0149, kp = 0.114, kd = 0.1655;
  const SampledPlantSpec di = double_integrator(J, 1.0, 1);
  RowVectorXd k(2);
  k << -kp, -kd;
  const Loop loop{{di.A, di.B, di.C, MatrixXd::Zero(2, 1), 0.0}, gains(k, 0.0)};
  const LoopMargins m = analyse_margins(loop);
  const double wgc = std::sqrt((kd * kd + std::sqrt(kd * kd * kd * kd + 4 * J * J * kp * kp)) / (2 * J * J));
  const double pm = std::atan(kd * wgc / kp);
  ASSERT_TRUE(m.closed_loop_stable);
  EXPECT_EQ(m.open_loop_marginal_poles, 2);
  EXPECT_EQ(m.open_loop_unstable_poles, 0);
  ASSERT_EQ(m.phase_margin.status, MarginStatus::kFinite);
  EXPECT_NEAR(m.phase_margin.frequency_rad_s, wgc, 1e-9 * wgc);
  EXPECT_NEAR(m.phase_margin.value, pm, 1e-9);
  EXPECT_NEAR(m.delay_margin.value, pm / wgc, 1e-9);
  EXPECT_EQ(m.gain_margin.status, MarginStatus::kInfinite);
  EXPECT_EQ(m.gain_reduction_margin.status, MarginStatus::kInfinite);
  EXPECT_TRUE(m.phase_crossovers_rad_s.empty());
}

TEST(MarginsTest, ZohIntegratorUnderProportionalControlMatchesTheClosedForm) {
  // ZOH of 1/s at period T is T/(z - 1); with u = -k x: L(z) = k T / (z - 1).
  // |L| = k T / (2 sin(w T / 2)) = 1 at w = (2/T) asin(k T / 2); angle L = -90 deg - w T / 2, so
  // PM = pi/2 - w T / 2; the phase crossover is at Nyquist, L(-1) = -k T / 2: GM = 2 / (k T).
  const double T = 0.02, k = 30.0;
  SampledPlantSpec s;
  s.A = MatrixXd::Zero(1, 1);
  s.B = MatrixXd::Ones(1, 1);
  s.C = MatrixXd::Ones(1, 1);
  s.tick_s = T / 2;
  s.ticks_per_sample = 2;
  const Loop loop{sample_plant(s), gains(RowVectorXd::Constant(1, -k), T)};
  const LoopMargins m = analyse_margins(loop);
  const double wgc = 2.0 / T * std::asin(k * T / 2.0);
  ASSERT_TRUE(m.closed_loop_stable);
  ASSERT_EQ(m.phase_margin.status, MarginStatus::kFinite);
  EXPECT_NEAR(m.phase_margin.frequency_rad_s, wgc, 1e-8 * wgc);
  EXPECT_NEAR(m.phase_margin.value, kPi / 2 - wgc * T / 2, 1e-9);
  ASSERT_EQ(m.gain_margin.status, MarginStatus::kFinite);
  EXPECT_NEAR(m.gain_margin.value, 2.0 / (k * T), 1e-9);
  EXPECT_NEAR(m.gain_margin.frequency_rad_s, kPi / T, 1e-9);
  // The closed-loop pole is z = 1 - k T.
  ASSERT_EQ(m.closed_loop_poles.size(), 1);
  EXPECT_NEAR(m.closed_loop_poles(0).real(), 1.0 - k * T, 1e-12);
}

TEST(MarginsTest, SampledDoubleIntegratorResponseIsTheZohTransferFunction) {
  // ZOH of 1/(J s^2): x/u = T^2 (z + 1) / (2 J (z - 1)^2), v/u = T / (J (z - 1)); with PD on the
  // measured x and v: L(z) = kp T^2 (z + 1) / (2 J (z - 1)^2) + kd T / (J (z - 1)).
  const double J = 0.0153, kp = 0.114, kd = 0.1658, tick = 0.01;
  const int N = 2;
  const double T = tick * N;
  const Loop loop = pd_loop(J, kp, kd, tick, N);
  for (double w : {0.05, 0.7, 3.0, 11.0, 60.0, 150.0}) {
    const std::complex<double> z = std::polar(1.0, w * T);
    const std::complex<double> expected =
        kp * T * T * (z + 1.0) / (2 * J * (z - 1.0) * (z - 1.0)) + kd * T / (J * (z - 1.0));
    const std::complex<double> got = loop.transfer(w);
    EXPECT_NEAR(std::abs(got - expected), 0.0, 1e-9 * std::abs(expected)) << "at " << w << " rad/s";
  }
}

TEST(MarginsTest, WholeSampleDelayLowersThePhaseMarginByOmegaGcTimesTheDelay) {
  const double J = 0.0149, kp = 0.114, kd = 0.1655, tick = 0.01;
  const int N = 2;
  const LoopMargins base = analyse_margins(pd_loop(J, kp, kd, tick, N));
  ASSERT_EQ(base.phase_margin.status, MarginStatus::kFinite);
  const double wgc = base.phase_margin.frequency_rad_s;
  for (int samples : {1, 2, 3}) {
    const LoopMargins d = analyse_margins(pd_loop(J, kp, kd, tick, N, samples * N));
    ASSERT_EQ(d.phase_margin.status, MarginStatus::kFinite);
    EXPECT_NEAR(d.phase_margin.frequency_rad_s, wgc, 1e-7 * wgc);  // a delay leaves |L| alone
    EXPECT_NEAR(d.phase_margin.value, base.phase_margin.value - wgc * samples * N * tick, 1e-7);
    EXPECT_NEAR(d.delay_margin.value, base.delay_margin.value - samples * N * tick, 1e-7);
    EXPECT_LT(d.gain_margin.value, base.gain_margin.value);
  }
  // A delay of one plant tick (half a controller sample) is not a pure phase shift of the sampled
  // loop, but close to one at a crossover far below Nyquist.
  const LoopMargins half = analyse_margins(pd_loop(J, kp, kd, tick, N, 1));
  EXPECT_NEAR(half.phase_margin.value, base.phase_margin.value - wgc * tick, 0.05 * wgc * tick);
}

TEST(MarginsTest, DelayMarginPredictsTheDelayThatDestabilises) {
  // A stiff PD whose delay margin is a few samples: every whole-sample delay below it keeps the
  // closed loop stable (eigenvalues), every one above it does not.
  const double J = 0.0149, kp = 2.0, kd = 0.12, tick = 0.01;
  const int N = 1;
  const LoopMargins m = analyse_margins(pd_loop(J, kp, kd, tick, N));
  ASSERT_EQ(m.delay_margin.status, MarginStatus::kFinite);
  const double samples = m.delay_margin.value / tick;
  ASSERT_GT(samples, 1.5);
  ASSERT_LT(samples, 8.0);
  for (int n = 0; n <= 10; ++n) {
    const Loop d = pd_loop(J, kp, kd, tick, N, n);
    const bool stable = unstable_count(closed_loop_poles(d), true, 0.0) == 0;
    if (n < samples - 0.05) {
      EXPECT_TRUE(stable) << n << " samples, margin " << samples;
    } else if (n > samples + 0.05) {
      EXPECT_FALSE(stable) << n << " samples, margin " << samples;
    }
  }
}

TEST(MarginsTest, GainMarginIsWhereTheEigenvaluesLeaveTheUnitCircle) {
  const Loop loop = pd_loop(0.0149, 0.114, 0.1655, 0.01, 2, 1);
  const LoopMargins m = analyse_margins(loop);
  ASSERT_EQ(m.gain_margin.status, MarginStatus::kFinite);
  const double g = m.gain_margin.value;
  EXPECT_EQ(unstable_count(closed_loop_poles(loop, g * (1 - 1e-6)), true, 0.0), 0);
  EXPECT_GT(unstable_count(closed_loop_poles(loop, g * (1 + 1e-6)), true, 0.0), 0);
  // |L| at the phase crossover is 1 / GM.
  EXPECT_NEAR(std::abs(loop.transfer(m.gain_margin.frequency_rad_s)), 1.0 / g, 1e-9);
}

TEST(MarginsTest, SlowerControllerLosesPhaseAsTheHoldDelayGrows) {
  // The hold acts as a delay of about T/2 at frequencies well below Nyquist: PM(T) ~ PM_c - w_gc T/2.
  const double J = 0.0149, kp = 0.114, kd = 0.1655, tick = 0.001;
  const SampledPlantSpec di = double_integrator(J, 1.0, 1);
  RowVectorXd k(2);
  k << -kp, -kd;
  const LoopMargins c = analyse_margins({{di.A, di.B, di.C, MatrixXd::Zero(2, 1), 0.0}, gains(k, 0.0)});
  double previous = c.phase_margin.value;
  for (int N : {1, 5, 10, 20, 40}) {
    const LoopMargins m = analyse_margins(pd_loop(J, kp, kd, tick, N));
    const double T = tick * N;
    EXPECT_LT(m.phase_margin.value, previous) << "T = " << T;
    EXPECT_NEAR(m.phase_margin.value, c.phase_margin.value - c.phase_margin.frequency_rad_s * T / 2,
                0.1 * c.phase_margin.frequency_rad_s * T / 2 + 1e-6)
        << "T = " << T;
    previous = m.phase_margin.value;
  }
}

TEST(MarginsTest, OpenLoopUnstablePlantHasALowerGainMargin) {
  // dx/dt = a x + u, u = -k x: stable for k > a. Nominal k = 3a: the gain may drop to a / k = 1/3
  // and grow without bound; L = k / (s - a) crosses the negative real axis at omega = 0.
  const double a = 2.0, k = 6.0;
  const StateSpace plant{MatrixXd::Constant(1, 1, a), MatrixXd::Ones(1, 1), MatrixXd::Ones(1, 1), MatrixXd::Zero(1, 1),
                         0.0};
  LoopMargins m = analyse_margins({plant, gains(RowVectorXd::Constant(1, -k), 0.0)}, {1e-6, 1e4, 4000});
  EXPECT_EQ(m.open_loop_unstable_poles, 1);
  ASSERT_TRUE(m.closed_loop_stable);
  EXPECT_EQ(m.gain_margin.status, MarginStatus::kInfinite);
  ASSERT_EQ(m.gain_reduction_margin.status, MarginStatus::kFinite);
  EXPECT_NEAR(m.gain_reduction_margin.value, a / k, 1e-6);
  // |L| = 1 at w = sqrt(k^2 - a^2); L = k / (j w - a) has angle -pi + atan(w / a): PM = atan(w / a).
  const double w = std::sqrt(k * k - a * a);
  EXPECT_NEAR(m.phase_margin.frequency_rad_s, w, 1e-8 * w);
  EXPECT_NEAR(m.phase_margin.value, std::atan(w / a), 1e-9);
  // Nominal gain below a: unstable, no margin is defined.
  m = analyse_margins({plant, gains(RowVectorXd::Constant(1, -1.0), 0.0)});
  EXPECT_FALSE(m.closed_loop_stable);
  EXPECT_EQ(m.gain_margin.status, MarginStatus::kUndefined);
  EXPECT_EQ(m.phase_margin.status, MarginStatus::kUndefined);
  EXPECT_EQ(m.delay_margin.status, MarginStatus::kUndefined);
  ASSERT_EQ(m.stable_gain_ranges.size(), 1u);  // but gains above a would do
  EXPECT_NEAR(m.stable_gain_ranges[0].first, a, 1e-6);
}

TEST(HoverLoopsTest, ContinuousAttitudeLoopsHaveTheLqrClosedLoopPoles) {
  const controllers::PaperParams params;
  const model::VehicleParams vehicle;
  const controllers::PaperController fc(vehicle, params);
  LoopTiming t;
  t.continuous = true;
  const std::vector<HoverLoop> loops = hover_loops(vehicle, fc, control::Mode::kAttitude, t);
  ASSERT_EQ(loops.size(), 4u);
  for (int i = 0; i < 3; ++i) {
    Eigen::VectorXcd got = closed_loop_poles(loops[static_cast<std::size_t>(i)].loop);
    ASSERT_EQ(got.size(), 2);
    Eigen::Vector2cd want = fc.axis(i).closed_loop_poles;
    auto by_real = [](const std::complex<double>& a, const std::complex<double>& b) { return a.real() < b.real(); };
    std::sort(got.begin(), got.end(), by_real);
    std::sort(want.begin(), want.end(), by_real);
    for (int j = 0; j < 2; ++j)
      EXPECT_NEAR(std::abs(got(j) - want(j)), 0.0, 1e-9) << loops[static_cast<std::size_t>(i)].name;
  }
  // Altitude: m s^2 + kd s + kp.
  const Eigen::VectorXcd alt = closed_loop_poles(loops[3].loop);
  for (Eigen::Index j = 0; j < alt.size(); ++j) {
    const std::complex<double> s = alt(j);
    EXPECT_NEAR(std::abs(vehicle.mass_kg * s * s + params.altitude.kd * s + params.altitude.kp), 0.0, 1e-9);
  }
}

TEST(HoverLoopsTest, FastSampledLoopsApproachTheContinuousPoles) {
  const model::VehicleParams vehicle;
  const controllers::PaperController fc(vehicle);
  LoopTiming t;
  t.tick_s = 1e-4;
  t.controller_divider = 1;
  const std::vector<HoverLoop> loops = hover_loops(vehicle, fc, control::Mode::kAttitude, t);
  for (int i = 0; i < 3; ++i) {
    const Eigen::VectorXcd z = closed_loop_poles(loops[static_cast<std::size_t>(i)].loop);
    for (Eigen::Index j = 0; j < z.size(); ++j) {
      const std::complex<double> s = std::log(z(j)) / t.tick_s;
      const double d =
          std::min(std::abs(s - fc.axis(i).closed_loop_poles(0)), std::abs(s - fc.axis(i).closed_loop_poles(1)));
      EXPECT_LT(d, 1e-3 * std::abs(s)) << loops[static_cast<std::size_t>(i)].name << " pole " << s;
    }
  }
}

TEST(HoverLoopsTest, PositionModeAddsTwoLoopsAndAnIntegratorOnlyWithKi) {
  controllers::PaperParams params;
  params.position = {0.8, 0.005, 1.4, 2.0, 0.35};
  params.roll = params.pitch = {1.0, 0.02, 1.0};
  const model::VehicleParams vehicle;
  const std::vector<HoverLoop> loops =
      hover_loops(vehicle, controllers::PaperController(vehicle, params), control::Mode::kPosition, {});
  ASSERT_EQ(loops.size(), 6u);
  EXPECT_EQ(loops[4].name, "position_x");
  EXPECT_EQ(loops[5].name, "position_y");
  EXPECT_EQ(loops[4].loop.controller.A.rows(), 1);
  for (const HoverLoop& l : loops) EXPECT_TRUE(analyse_margins(l.loop).closed_loop_stable) << l.name;
  // Broken anywhere, the closed loop is the same system: the pitch loop at the torque and the x loop
  // at the tilt setpoint have the same closed-loop poles.
  auto sorted = [](Eigen::VectorXcd p) {
    std::sort(p.begin(), p.end(),
              [](auto a, auto b) { return a.real() != b.real() ? a.real() < b.real() : a.imag() < b.imag(); });
    return p;
  };
  const Eigen::VectorXcd a = sorted(closed_loop_poles(loops[1].loop)), b = sorted(closed_loop_poles(loops[4].loop));
  ASSERT_EQ(a.size(), b.size());
  for (Eigen::Index j = 0; j < a.size(); ++j) EXPECT_NEAR(std::abs(a(j) - b(j)), 0.0, 1e-8);
  params.position.ki = 0.0;
  EXPECT_EQ(hover_loops(vehicle, controllers::PaperController(vehicle, params), control::Mode::kPosition, {})[4]
                .loop.controller.A.rows(),
            0);
}

TEST(HoverLoopsTest, AVehicleThatCannotHoverIsRefusedByName) {
  model::VehicleParams v;
  v.motor.omega_max_rad_s = 4000.0;
  EXPECT_NE(hover_trim_problem(v).find("omega_max"), std::string::npos) << hover_trim_problem(v);
  EXPECT_THROW(hover_loops(v, controllers::PaperController(v), control::Mode::kAttitude, {}), std::invalid_argument);
  EXPECT_EQ(hover_trim_problem(model::VehicleParams{}), "");
}

// The sampled loops against the nonlinear simulation: from a small offset in roll and height, the
// simulated roll and height at each control tick follow the linear closed loop's free response, with
// the plant's command delay, IMU/pose latency and motor lag as the simulation applies them.
struct CrossCheckCase {
  int command_delay_ticks, imu_latency_ticks, pose_latency_ticks;
  bool motor_lag;
};

class SimulationCrossCheck : public ::testing::TestWithParam<CrossCheckCase> {};

TEST_P(SimulationCrossCheck, LinearLoopsPredictTheSimulatedFreeResponse) {
  const CrossCheckCase c = GetParam();
  model::VehicleParams v;
  if (c.motor_lag) {
    v.motor.model = model::MotorModel::kFirstOrder;
    v.motor.tau_up_s = v.motor.tau_down_s = 0.015;  // symmetric: linear about hover
  }
  control::ControllerConfig controller = controllers::make_config("paper", v);
  controller.node.setpoint.p_des_W.z() = 10.0;
  sim::SimulationConfig cfg;
  cfg.duration_ticks = 400;
  cfg.plant.command_delay_ticks = c.command_delay_ticks;
  cfg.plant.realism.imu.timing.latency_ticks = c.imu_latency_ticks;
  cfg.plant.realism.pose.timing.latency_ticks = c.pose_latency_ticks;
  cfg.plant.watchdog_ticks = 0;
  const double roll0 = 0.01, dz0 = 0.02;
  model::State x0;
  x0.p_W = {0, 0, 10.0 + dz0};
  x0.q_WB = Eigen::Quaterniond(Eigen::AngleAxisd(roll0, Eigen::Vector3d::UnitX()));
  x0.omega_rad_s.setConstant(v.hover_omega_rad_s());
  sim::Simulation sim(cfg, v, x0, controller, {});
  std::vector<double> roll, z;
  sim.run([&](const sim::TickRecord& r) {
    roll.push_back(model::euler_from_quaternion(r.state.q_WB).roll_rad);
    z.push_back(r.state.p_W.z() - 10.0);
  });

  LoopTiming t;
  t.command_delay_ticks = c.command_delay_ticks;
  t.imu_latency_ticks = c.imu_latency_ticks;
  t.pose_latency_ticks = c.pose_latency_ticks;
  const std::vector<HoverLoop> loops =
      hover_loops(v, *controllers::paper_controller(controller), control::Mode::kAttitude, t);
  // Free response of each closed loop from x(0) = offset, delay lines holding the hover command
  // (deviation 0) and the measurements of tick 0 (the plant publishes max(k - L, 0)).
  auto predict = [&](const HoverLoop& l, double offset, int latency) {
    const Eigen::MatrixXd A = l.loop.closed_loop_matrix(1.0);
    Eigen::VectorXd X = Eigen::VectorXd::Zero(A.rows());
    X(0) = offset;
    const Eigen::Index n_plant = c.motor_lag ? 3 : 2;
    const Eigen::Index lines = n_plant + c.command_delay_ticks;
    if (latency > 0) X.segment(lines, latency).setConstant(offset);  // the angle's / height's line
    std::vector<double> out;
    for (int j = 0; j * 2 <= cfg.duration_ticks; ++j) {
      out.push_back(X(0));
      X = A * X;
    }
    return out;
  };
  const std::vector<double> roll_lin = predict(loops[0], roll0, c.imu_latency_ticks);
  const std::vector<double> z_lin = predict(loops[3], dz0, c.pose_latency_ticks);
  double roll_err = 0.0, z_err = 0.0;
  for (std::size_t j = 0; j < roll_lin.size(); ++j) {
    roll_err = std::max(roll_err, std::abs(roll[2 * j] - roll_lin[j]));
    z_err = std::max(z_err, std::abs(z[2 * j] - z_lin[j]));
  }
  // Roll: the plant is linear in it up to RK4's error on the motor lag (measured <= 1.1e-7 rad);
  // height: the roll offset tilts the thrust (second order, measured <= 5e-6 m). A delay or latency
  // modelled one tick wrong gives errors over 3e-5 rad and 9e-5 m.
  EXPECT_LT(roll_err, 1e-4 * roll0);
  EXPECT_LT(z_err, 5e-4 * dz0);
  // And it is a real test: the response moves by far more than the error allowed.
  EXPECT_LT(roll_lin.back(), 0.5 * roll0);
}

// Position mode: from a small horizontal offset, x and y follow the free response of the position
// loops (broken at the tilt setpoint; the closed loop includes attitude and the PID's integrator),
// which checks the signs and the gravity coupling of the horizontal channels against the plant.
TEST(SimulationCrossCheckPosition, PositionLoopsPredictTheSimulatedFreeResponse) {
  controllers::PaperParams params;
  params.roll = params.pitch = {1.0, 0.02, 1.0};
  params.position = {0.8, 0.005, 1.4, 2.0, 0.35};
  const model::VehicleParams v;
  control::ControllerConfig controller = controllers::make_config("paper", v);
  controller.controller = std::make_shared<controllers::PaperController>(v, params);
  controller.node.setpoint.mode = control::Mode::kPosition;
  controller.node.setpoint.p_des_W = {0.0, 0.0, 5.0};
  sim::SimulationConfig cfg;
  cfg.duration_ticks = 800;
  cfg.plant.command_delay_ticks = 1;
  cfg.plant.watchdog_ticks = 0;
  const double x0 = 0.02, y0 = -0.015;
  model::State s0;
  s0.p_W = {x0, y0, 5.0};
  s0.omega_rad_s.setConstant(v.hover_omega_rad_s());
  sim::Simulation sim(cfg, v, s0, controller, {});
  std::vector<double> x, y;
  sim.run([&](const sim::TickRecord& r) {
    x.push_back(r.state.p_W.x());
    y.push_back(r.state.p_W.y());
  });
  LoopTiming t;
  t.command_delay_ticks = 1;
  const std::vector<HoverLoop> loops =
      hover_loops(v, *controllers::paper_controller(controller), control::Mode::kPosition, t);
  ASSERT_EQ(loops[4].name, "position_x");
  auto predict = [&](const HoverLoop& l, double offset) {
    const Eigen::MatrixXd A = l.loop.closed_loop_matrix(1.0);
    Eigen::VectorXd X = Eigen::VectorXd::Zero(A.rows());
    X(0) = offset;  // [p, v, angle, rate], the command line (hover), the PID's integral (0)
    std::vector<double> out;
    for (int j = 0; j * 2 <= cfg.duration_ticks; ++j) {
      out.push_back(X(0));
      X = A * X;
    }
    return out;
  };
  const std::vector<double> x_lin = predict(loops[4], x0), y_lin = predict(loops[5], y0);
  double x_err = 0.0, y_err = 0.0;
  for (std::size_t j = 0; j < x_lin.size(); ++j) {
    x_err = std::max(x_err, std::abs(x[2 * j] - x_lin[j]));
    y_err = std::max(y_err, std::abs(y[2 * j] - y_lin[j]));
  }
  EXPECT_LT(x_err, 1e-4 * x0);
  EXPECT_LT(y_err, 1e-4 * std::abs(y0));
  EXPECT_LT(std::abs(x_lin.back()), 0.2 * x0);  // it moved: the check has teeth
}

INSTANTIATE_TEST_SUITE_P(Timings, SimulationCrossCheck,
                         ::testing::Values(CrossCheckCase{0, 0, 0, false}, CrossCheckCase{1, 0, 0, false},
                                           CrossCheckCase{3, 1, 2, false}, CrossCheckCase{2, 1, 0, true}));

}  // namespace
}  // namespace quadcosim::analysis
