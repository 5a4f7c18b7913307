// A vehicle with more than four rotors through the co-simulation layer: the plant's command intake
// takes one speed per rotor and refuses another length by name, and a closed loop flies it.
#include <gtest/gtest.h>

#include <cmath>
#include <string>

#include "controllers/registry.hpp"
#include "model/quadrotor.hpp"
#include "sim/plant_core.hpp"
#include "sim/simulation.hpp"
#include "sim/validation.hpp"

namespace quadcosim::sim {
namespace {

model::VehicleParams hex() {
  model::VehicleParams v;
  v.set_layout(model::RotorLayout::kHexX);
  return v;
}

msg::Float64MultiArray speeds(std::initializer_list<double> w) {
  msg::Float64MultiArray m;
  m.data.assign(w);
  return m;
}

TEST(RotorsSim, AHexPlantTakesSixSpeedsAndRefusesFourByName) {
  const model::VehicleParams v = hex();
  const TickClock clock{10'000'000};
  PlantCore p(v, {}, clock, model::Quadrotor(v).initial_state({0.0, 0.0, 5.0}, 0.0, true), "/drone");
  ASSERT_EQ(p.latched().size(), 6);

  const CommandCheck four = p.take_command(0, 0, speeds({500.0, 500.0, 500.0, 500.0}));
  EXPECT_EQ(four.verdict(), CommandVerdict::kRejected);
  EXPECT_EQ(four.fault, CommandFault::kWrongLength);
  EXPECT_EQ(four.reason(), "4 values, expected 6 rotor speeds");

  const CommandCheck six = p.take_command(0, 0, speeds({100.0, 200.0, 300.0, 400.0, 500.0, 20000.0}));
  EXPECT_EQ(six.verdict(), CommandVerdict::kClamped);
  EXPECT_EQ(six.rotor, 5);  // rotor 6, above omega_max
  EXPECT_NE(six.reason().find("rotor 6 speed 20000 rad/s clamped to 12000"), std::string::npos) << six.reason();
  p.latch_due(0);
  ASSERT_EQ(p.latched().size(), 6);
  EXPECT_EQ(p.latched()[0], 100.0);
  EXPECT_EQ(p.latched()[5], v.motor.omega_max_rad_s);

  // rotor_thrusts is a four-rotor level.
  msg::Float64MultiArray thrusts = speeds({1.0, 1.0, 1.0, 1.0});
  msg::set_command_level(thrusts, "rotor_thrusts");
  const CommandCheck t = p.take_command(1, 0, thrusts);
  EXPECT_EQ(t.verdict(), CommandVerdict::kRejected);
  EXPECT_NE(t.reason().find("this vehicle has 6 rotors"), std::string::npos) << t.reason();

  // The watchdog's stop latches omega_min on all six.
  p.latch_omega_min();
  EXPECT_EQ(p.latched(), model::RotorVector::Zero(6));
}

TEST(RotorsSim, TheSe3ControllerHoldsAHexInTheLoop) {
  const model::VehicleParams v = hex();
  SimulationConfig cfg;
  cfg.duration_ticks = 800;
  control::ControllerConfig controller = controllers::make_config("se3", v);
  controller.node.setpoint.mode = control::Mode::kPosition;
  controller.node.setpoint.p_des_W = {0.0, 0.0, 2.0};
  const model::State x0 = model::Quadrotor(v).initial_state({0.3, -0.2, 1.5}, 0.0, true);
  Simulation s(cfg, v, x0, controller, {});
  int statuses = 0;
  for (Tick k = 0; k <= cfg.duration_ticks; ++k) {
    s.tick(k, [&](const TickRecord& r) {
      ASSERT_EQ(r.latched_command.size(), 6);
      for (std::size_t i = 6; i < 8; ++i) EXPECT_FALSE(r.status.rotor_saturated[i]);
      ++statuses;
    });
  }
  EXPECT_GT(statuses, 0);
  const model::State& x = s.plant().state();
  EXPECT_LT((x.p_W - Eigen::Vector3d(0.0, 0.0, 2.0)).norm(), 0.02) << x.p_W.transpose();
}

}  // namespace
}  // namespace quadcosim::sim
