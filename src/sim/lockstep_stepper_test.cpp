// Tests of the lockstep controller host: it steps on complete samples of control ticks only, on the
// sample's own time, answers a repeated tick again with the same command, applies the schedule by
// simulated time, and reproduces the in-process Simulation's trajectory bit for bit.
#include <gtest/gtest.h>

#include <stdexcept>
#include <vector>

#include "controllers/registry.hpp"
#include "sim/controller_node.hpp"
#include "sim/inprocess_transport.hpp"
#include "sim/lockstep_stepper.hpp"
#include "sim/plant_node.hpp"
#include "sim/simulation.hpp"

namespace quadcosim::sim {
namespace {

// A plant on a bus and a controller hosted by a LockstepStepper, as `quadcosim controller` runs it.
struct LockstepRig {
  InProcessTransport bus;
  Topics topics = Topics::for_namespace("/drone");
  control::ControllerConfig cfg = controllers::make_config("paper", model::VehicleParams{});
  std::vector<msg::Float64MultiArray> commands;
  std::unique_ptr<PlantNode> plant;
  std::unique_ptr<ControllerNode> node;
  std::unique_ptr<LockstepStepper> stepper;

  explicit LockstepRig(std::vector<ScheduledParameter> schedule = {}, model::State x0 = {}) {
    bus.subscribe<msg::Float64MultiArray>(topics.motor_commands,
                                          [this](const msg::Float64MultiArray& m) { commands.push_back(m); });
    plant = std::make_unique<PlantNode>(bus, topics, cfg.vehicle, PlantOptions{}, x0);
    node = std::make_unique<ControllerNode>(bus, topics, cfg);
    stepper = std::make_unique<LockstepStepper>(*node, std::move(schedule), TickClock{}, 2);
  }
};

TEST(LockstepStepperTest, StepsOnCompleteSamplesOfControlTicksOnly) {
  LockstepRig rig;
  rig.plant->publish_outputs(0);  // Pose, Velocity, Imu of t = 0: one complete sample, a control tick
  ASSERT_EQ(rig.commands.size(), 1u);
  EXPECT_EQ(rig.node->last_step_ns(), 0);
  rig.plant->publish_outputs(1);  // t = 10 ms: complete, but the controller runs at 50 Hz
  EXPECT_EQ(rig.commands.size(), 1u);
  rig.plant->publish_outputs(2);
  ASSERT_EQ(rig.commands.size(), 2u);
  EXPECT_EQ(rig.node->last_step_ns(), 20'000'000);
  EXPECT_EQ(rig.commands[1].dim.at(0).label, "rotors@20000000");
}

TEST(LockstepStepperTest, AnIncompleteSampleIsNotStepped) {
  LockstepRig rig;
  Publisher<msg::PoseStamped> pose = rig.bus.advertise<msg::PoseStamped>(rig.topics.pose);
  msg::PoseStamped p;
  p.header.stamp = msg::Time::from_ns(40'000'000);
  p.orientation.w = 1.0;
  pose.publish(p);  // Pose of t = 40 ms alone, nothing else of that tick
  EXPECT_TRUE(rig.commands.empty());
  EXPECT_EQ(rig.node->synchronized_stamp_ns(), -1);
}

TEST(LockstepStepperTest, ARepeatedTickIsAnsweredAgainWithTheSameCommand) {
  model::State x0;
  x0.p_W.z() = 1.0;
  LockstepRig rig({}, x0);
  rig.plant->publish_outputs(0);
  ASSERT_EQ(rig.commands.size(), 1u);
  rig.plant->publish_outputs(0);  // the plant asks again for t = 0
  ASSERT_GT(rig.commands.size(), 1u);
  for (const auto& c : rig.commands) {
    EXPECT_EQ(c.data, rig.commands[0].data);
    EXPECT_EQ(c.dim.at(0).label, "rotors@0");
  }
  EXPECT_EQ(rig.node->last_step_ns(), 0);  // no second step: the integrators did not move
}

TEST(LockstepStepperTest, AppliesTheScheduleBySimulatedTime) {
  LockstepRig rig({{6, "z_des", 3.0}});  // at tick 6 = 60 ms
  for (Tick k = 0; k <= 4; ++k) rig.plant->publish_outputs(k);
  EXPECT_EQ(rig.node->settings().setpoint.p_des_W.z(), rig.cfg.node.setpoint.p_des_W.z());
  rig.plant->publish_outputs(5);
  EXPECT_EQ(rig.node->settings().setpoint.p_des_W.z(), rig.cfg.node.setpoint.p_des_W.z());
  rig.plant->publish_outputs(6);
  EXPECT_EQ(rig.node->settings().setpoint.p_des_W.z(), 3.0);
}

TEST(LockstepStepperTest, ARefusedScheduledParameterIsAnErrorNamingIt) {
  LockstepRig rig({{0, "no_such_gain", 1.0}});
  try {
    rig.plant->publish_outputs(0);
    FAIL() << "no error";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("no_such_gain"), std::string::npos) << e.what();
  }
}

TEST(LockstepStepperTest, UnhooksWhenDestroyed) {
  LockstepRig rig;
  rig.stepper.reset();
  rig.plant->publish_outputs(0);
  EXPECT_TRUE(rig.commands.empty());
}

TEST(LockstepStepperTest, FliesTheSameBitsAsTheInProcessSimulation) {
  // The reference: Simulation (schedule before the outputs, controller stepped by the tick).
  const std::vector<ScheduledParameter> schedule = {{50, "z_des", 1.0}, {120, "yaw_des", 0.3}};
  SimulationConfig sc;
  sc.duration_ticks = 300;
  const control::ControllerConfig controller = controllers::make_config("paper", model::VehicleParams{});
  Simulation reference(sc, controller.vehicle, {}, controller, schedule);
  std::vector<model::State> expected;
  reference.run([&](const TickRecord& r) { expected.push_back(r.state); });

  // The same loop driven as over DDS: the plant publishes, the stepper reacts on the sample.
  LockstepRig rig(schedule);
  std::vector<model::State> got;
  for (Tick k = 0; k <= sc.duration_ticks; ++k) {
    rig.plant->publish_outputs(k);
    rig.plant->latch_command(k);
    got.push_back(rig.plant->state());
    if (k < sc.duration_ticks) rig.plant->integrate(k);
  }
  ASSERT_EQ(got.size(), expected.size());
  EXPECT_GT(expected.back().p_W.z(), 0.5);  // it climbed: the schedule acted
  for (std::size_t i = 0; i < got.size(); ++i) {
    const model::State &a = got[i], &b = expected[i];
    ASSERT_TRUE(a.p_W == b.p_W && a.v_W == b.v_W && a.q_WB.coeffs() == b.q_WB.coeffs() && a.w_B == b.w_B &&
                a.omega_rad_s == b.omega_rad_s)
        << "tick " << i;
  }
}

}  // namespace
}  // namespace quadcosim::sim
