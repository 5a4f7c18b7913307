// The example controller flown in-process on the plant (sim::Simulation), as every controller can be:
// an altitude step in attitude mode and a circle in position mode, against bounds from its gains.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include "controllers/example_pd/example_pd_controller.hpp"
#include "controllers/registry.hpp"
#include "model/quadrotor.hpp"
#include "sim/simulation.hpp"
#include "trajectory/periodic.hpp"

namespace qc = quadcosim;

namespace {
qc::sim::SimulationConfig config(double duration_s) {
  qc::sim::SimulationConfig c;
  c.duration_ticks = static_cast<qc::sim::Tick>(duration_s * 100);
  return c;
}
}  // namespace

TEST(ExamplePdController, ClimbsToTheAltitudeSetpointLikeASecondOrderLoop) {
  const qc::model::VehicleParams v;
  qc::control::ControllerConfig c = qc::controllers::make_config("example_pd", v);
  ASSERT_EQ(c.type(), "example_pd");
  ASSERT_EQ(qc::control::set_parameter(c, "z_des", 2.0), "");
  qc::sim::Simulation sim(config(10.0), v, qc::model::Quadrotor(v).initial_state({0, 0, 0}, 0.0, true), c, {});
  double z_max = 0.0, z_end = 0.0;
  sim.run([&](const qc::sim::TickRecord& r) {
    z_max = std::max(z_max, r.state.p_W.z());
    z_end = r.state.p_W.z();
    ASSERT_EQ(r.status.controller, "example_pd");
  });
  // z'' = kp (2 - z) - kd z' with kp = 1, kd = 1.6 (zeta = 0.8): overshoot exp(-pi zeta / sqrt(1 - zeta^2))
  // = 1.5 %, settled to 1 cm within 10 s; allow the motor lag and the 50 Hz sampling a little more.
  const double zeta = 0.8;
  const double overshoot = std::exp(-std::numbers::pi * zeta / std::sqrt(1 - zeta * zeta));
  EXPECT_LT(z_max, 2.0 * (1 + overshoot) + 0.02);
  EXPECT_NEAR(z_end, 2.0, 0.01);
}

TEST(ExamplePdController, FollowsACircleWithinTheErrorOfItsLinearLoop) {
  const qc::model::VehicleParams v;
  qc::control::ControllerConfig c = qc::controllers::make_config("example_pd", v);
  qc::trajectory::CircleParams circle;  // r = 1 m, 10 s per lap at 1 m, about the origin
  c.trajectory = qc::trajectory::make_circle(circle);
  qc::sim::Simulation sim(config(30.0), v, qc::model::Quadrotor(v).initial_state({1, 0, 1}, 0.0, true), c, {});
  double worst = 0.0;
  sim.run([&](const qc::sim::TickRecord& r) {
    if (r.t_s < 15.0) return;
    const Eigen::Vector3d ref(r.status.setpoint[0], r.status.setpoint[1], r.status.setpoint[2]);
    worst = std::max(worst, (r.state.p_W - ref).norm());
  });
  // With the acceleration feedforward the error is that of the attitude loop's lag: far below the
  // radius.
  EXPECT_LT(worst, 0.2);
  EXPECT_GT(worst, 0.0);
}
