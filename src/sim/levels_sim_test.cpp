// Command levels on the plant side: a controller (or a stepping front end) that commands ctbr and the
// other levels through the in-process bus, the plant's intake of level commands, and bit identity
// between the bus and a bare PlantCore fed the same setpoints.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <memory>
#include <string>
#include <vector>

#include "control/command_level.hpp"
#include "control/controller.hpp"
#include "controllers/registry.hpp"
#include "model/attitude.hpp"
#include "sim/controller_core.hpp"
#include "sim/plant_core.hpp"
#include "sim/simulation.hpp"
#include "sim/validation.hpp"

namespace quadcosim::sim {
namespace {

/// The ctbr setpoint of control step j (a deterministic sequence: hover thrust with rate steps).
Eigen::Vector4d ctbr_at(const model::VehicleParams& v, Tick j) {
  const double t = 0.02 * static_cast<double>(j);
  return {v.mass_kg * v.gravity_m_s2 * (1.0 + 0.05 * std::sin(t)), t < 0.5 ? 0.3 : -0.1, 0.2 * std::cos(3.0 * t),
          t > 1.0 ? 0.05 : 0.0};
}

/// A controller that flies ctbr_at(step).
class CtbrController : public control::Controller {
 public:
  explicit CtbrController(const model::VehicleParams& v) : v_(v) {}
  std::string_view type() const override { return "ctbr_test"; }
  std::unique_ptr<control::Controller> clone() const override { return std::make_unique<CtbrController>(*this); }
  std::span<const control::ParameterSpec> parameters() const override { return {}; }
  std::optional<control::ParameterValue> get_parameter(std::string_view) const override { return std::nullopt; }
  std::string set_parameters(std::span<const control::Setting> s) override {
    return s.empty() ? "" : control::unknown_parameter(s.front().name);
  }
  std::span<const std::string> output_names() const override { return {}; }
  void reset() override { step_ = 0; }
  void step(const control::Observation&, const control::Reference&, double, control::ControllerOutput& out) override {
    out.level = control::CommandLevel::kCtbr;
    out.setpoint = ctbr_at(v_, step_++);
    out.omega_rad_s.setZero();
    out.U = out.setpoint;
  }

 private:
  model::VehicleParams v_;
  Tick step_ = 0;
};

model::State hover_at(const model::VehicleParams& v, double z) {
  return model::Quadrotor(v).initial_state({0.0, 0.0, z}, 0.0, true);
}

TEST(CommandLevels, AControllerFlyingCtbrOverTheBusEqualsABarePlantFedTheSameSetpoints) {
  SimulationConfig cfg;
  cfg.duration_ticks = 300;
  const model::VehicleParams v;
  control::ControllerConfig controller = controllers::make_config("paper", v);
  controller.controller = std::make_shared<CtbrController>(v);
  const model::State x0 = hover_at(v, 5.0);
  Simulation s(cfg, v, x0, controller, {});
  // The same plant without a bus: the setpoint of control step j queued at tick 2j (divider 2).
  PlantCore bare(v, cfg.plant.realism, cfg.plant.clock, x0, cfg.ns);
  for (Tick k = 0; k <= cfg.duration_ticks; ++k) {
    s.tick(k);
    if (k % cfg.controller_divider == 0) bare.queue(k, 0, ctbr_at(v, k / 2), control::CommandLevel::kCtbr);
    bare.latch(k, bare.command_age_ns(cfg.plant.clock, k), cfg.plant.clock.ns(cfg.plant.watchdog_ticks),
               cfg.plant.watchdog_policy);
    ASSERT_EQ(s.plant().latched_command(), bare.latched()) << "tick " << k;
    if (k < cfg.duration_ticks) bare.integrate(cfg.plant.clock, k, cfg.plant.substeps);  // as tick(k) does
    const model::State& a = s.plant().state();
    const model::State& b = bare.state();
    ASSERT_EQ(std::memcmp(a.p_W.data(), b.p_W.data(), sizeof(double) * 3), 0) << "tick " << k;
    ASSERT_EQ(std::memcmp(a.w_B.data(), b.w_B.data(), sizeof(double) * 3), 0) << "tick " << k;
    ASSERT_EQ(std::memcmp(a.q_WB.coeffs().data(), b.q_WB.coeffs().data(), sizeof(double) * 4), 0) << "tick " << k;
  }
  // The setpoint was flown: the first rate step (0.3 rad/s about x for 0.5 s) turned the vehicle.
  EXPECT_EQ(s.plant().state().q_WB.coeffs().allFinite(), true);
  EXPECT_GT(std::abs(model::euler_from_quaternion(s.plant().state().q_WB).roll_rad), 0.05);
  EXPECT_EQ(s.plant().core().held().level, control::CommandLevel::kCtbr);
}

TEST(CommandLevels, AnOverriddenLevelCommandIsHeldAndFlownEveryTick) {
  // Velocity 0.5 m/s up from hover at 10 m, given by a stepping front end (Simulation's override): the
  // vertical loop is first order, v_z(t) = 0.5 (1 - exp(-K_v t)) at the ticks (K_v 1.5 rad/s). tick(k)
  // ends with the state at t_k+1.
  SimulationConfig cfg;
  const model::VehicleParams v;
  const control::ControllerConfig controller = controllers::make_config("paper", v);
  Simulation s(cfg, v, hover_at(v, 10.0), controller, {});
  s.override_level_command(control::LevelCommand{control::CommandLevel::kVelocity, {0.0, 0.0, 0.5, 0.0}});
  double worst = 0.0;
  for (Tick k = 0; k <= 200; ++k) {
    s.tick(k);
    worst = std::max(
        worst, std::abs(s.plant().state().v_W.z() - 0.5 * (1.0 - std::exp(-1.5 * 0.01 * static_cast<double>(k + 1)))));
  }
  EXPECT_LT(worst, 1e-9);
  // Off again: the controller's rotor speeds, the level dimension gone from the command.
  s.override_level_command(std::nullopt);
  s.tick(201);
  s.tick(202);  // the controller's next step (divider 2)
  EXPECT_EQ(s.plant().core().held().level, control::CommandLevel::kRotorSpeeds);
}

TEST(CommandLevels, TheWatchdogsStopEndsALevelCommand) {
  const model::VehicleParams v;
  const TickClock clock{10'000'000};
  PlantCore p(v, {}, clock, hover_at(v, 10.0), "/drone");
  p.queue(0, 0, model::Vector4(v.mass_kg * v.gravity_m_s2, 0.0, 0.0, 0.0), control::CommandLevel::kCtbr);
  EXPECT_FALSE(p.latch(0, 0, clock.ns(50), WatchdogPolicy::kStop));
  EXPECT_EQ(p.held().level, control::CommandLevel::kCtbr);
  EXPECT_NEAR(v.kt_N_per_rad2_s2 * p.latched().cwiseAbs2().sum(), v.mass_kg * v.gravity_m_s2, 1e-12);
  EXPECT_TRUE(p.latch(60, clock.ns(60), clock.ns(50), WatchdogPolicy::kStop));
  EXPECT_EQ(p.held().level, control::CommandLevel::kRotorSpeeds);
  EXPECT_EQ(p.latched(), model::Vector4::Zero());
}

TEST(CommandLevels, LevelCommandsOnTheWireAreCheckedNamingWhatIsWrong) {
  msg::Float64MultiArray m;
  m.dim = {{msg::command_label(20'000'000), 4, 4}};
  m.data = {19.0, 0.1, 0.0, 0.0};
  msg::set_command_level(m, "ctbr");
  ASSERT_EQ(m.dim.size(), 2u);
  EXPECT_EQ(m.dim[1].label, "level=ctbr");
  EXPECT_EQ(msg::command_level_name(m), "ctbr");
  EXPECT_EQ(msg::command_stamp_ns(m), 20'000'000);  // the lockstep label still read
  CommandCheck c = check_command(m, 12000.0);
  EXPECT_EQ(c.verdict(), CommandVerdict::kAccepted);
  EXPECT_EQ(c.level, control::CommandLevel::kCtbr);
  EXPECT_EQ(c.omega_rad_s, Eigen::Vector4d(19.0, 0.1, 0.0, 0.0));
  m.data[2] = std::nan("");
  c = check_command(m, 12000.0);
  EXPECT_EQ(c.verdict(), CommandVerdict::kRejected);
  EXPECT_EQ(c.reason(), "ctbr value 3 (q [rad/s]) is nan, expected a finite number");
  m.data = {1.0, 2.0, 3.0};
  EXPECT_EQ(check_command(m, 12000.0).reason(), "3 values, expected 4 for level ctbr");
  m.data = {1.0, 2.0, 3.0, 4.0};
  msg::set_command_level(m, "ctrb");
  c = check_command(m, 12000.0);
  EXPECT_EQ(c.fault, CommandFault::kUnknownLevel);
  EXPECT_EQ(c.verdict(), CommandVerdict::kRejected);
  EXPECT_NE(c.reason().find("unknown command level 'ctrb'"), std::string::npos) << c.reason();
  msg::set_command_level(m, "rotor_thrusts");
  m.data = {1.0, -2.0, 3.0, -4.0};
  c = check_command(m, 12000.0);
  EXPECT_EQ(c.verdict(), CommandVerdict::kClamped);
  EXPECT_EQ(c.reason(), "rotor 2 thrust -2 N clamped to 0");
  EXPECT_EQ(c.omega_rad_s, Eigen::Vector4d(1.0, 0.0, 3.0, 0.0));
  msg::set_command_level(m, "rotor_speeds");  // rotor speeds: the level dimension removed
  EXPECT_EQ(m.dim.size(), 1u);
  // A controller's output at rotor speeds leaves the message as it always was.
  control::ControllerOutput out;
  out.omega_rad_s = model::Vector4(1.0, 2.0, 3.0, 4.0);
  msg::Float64MultiArray w;
  w.dim = {{msg::command_label(0), 4, 4}};
  write_command(out, w);
  EXPECT_EQ(w.dim.size(), 1u);
  EXPECT_EQ(w.data, (std::vector<double>{1.0, 2.0, 3.0, 4.0}));
  out.level = control::CommandLevel::kCttm;
  out.setpoint = {20.0, 0.0, 0.0, 0.01};
  write_command(out, w);
  EXPECT_EQ(msg::command_level_name(w), "cttm");
  EXPECT_EQ(w.data, (std::vector<double>{20.0, 0.0, 0.0, 0.01}));
}

}  // namespace
}  // namespace quadcosim::sim
