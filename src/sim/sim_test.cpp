// Tests of the co-simulation layer: transport, nodes, the multi-rate scheduler, determinism.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <vector>

#include "sim/controller_node.hpp"
#include "sim/inprocess_transport.hpp"
#include "sim/plant_node.hpp"
#include "sim/simulation.hpp"

namespace quadcosim::sim {
namespace {

TEST(TimeTest, FromNanosecondsSplitsSecondsAndNanoseconds) {
  EXPECT_EQ(msg::Time::from_ns(1'500'000'000).sec, 1);
  EXPECT_EQ(msg::Time::from_ns(1'500'000'000).nanosec, 500'000'000u);
  EXPECT_EQ(msg::Time::from_ns(-1).sec, -1);
  EXPECT_EQ(msg::Time::from_ns(-1).nanosec, 999'999'999u);
  EXPECT_EQ(msg::Time::from_ns(123'456'789'012).to_ns(), 123'456'789'012);
}

TEST(TickClockTest, TimeIsTickTimesPeriodNotASum) {
  TickClock c{10'000'000};
  double sum = 0.0;
  for (int i = 0; i < 1000; ++i) sum += 0.01;
  EXPECT_EQ(c.seconds(1000), 10.0);  // exact; the running sum is not
  EXPECT_NE(sum, 10.0);
  EXPECT_EQ(c.ns(1000), 10'000'000'000);
}

TEST(TopicsTest, NamespacedNames) {
  const Topics t = Topics::for_namespace("/uav1");
  EXPECT_EQ(t.pose, "/uav1/Pose");
  EXPECT_EQ(t.motor_commands, "/uav1/motor_commands");
  EXPECT_EQ(t.clock, "/clock");
  EXPECT_EQ(Topics::for_namespace("/").pose, "/Pose");
  EXPECT_EQ(validate_namespace("/drone"), "");
  EXPECT_NE(validate_namespace("drone"), "");
  EXPECT_NE(validate_namespace("/a//b"), "");
  EXPECT_NE(validate_namespace("/1uav"), "");
  EXPECT_NE(validate_namespace("/uav-1"), "");
}

TEST(InProcessTransportTest, DeliversInOrderToEverySubscriber) {
  InProcessTransport bus;
  std::vector<int> seen;
  bus.subscribe<msg::Clock>("/clock", [&](const msg::Clock& c) { seen.push_back(10 + c.clock.sec); });
  bus.subscribe<msg::Clock>("/clock", [&](const msg::Clock& c) { seen.push_back(20 + c.clock.sec); });
  auto pub = bus.advertise<msg::Clock>("/clock");
  pub.publish(msg::Clock{{1, 0}});
  pub.publish(msg::Clock{{2, 0}});
  EXPECT_EQ(seen, (std::vector<int>{11, 21, 12, 22}));
  EXPECT_EQ(bus.delivered("/clock"), 2u);
  EXPECT_EQ(bus.delivered("/other"), 0u);
}

TEST(InProcessTransportTest, RefusesASecondTypeOnOneTopic) {
  InProcessTransport bus;
  auto pub = bus.advertise<msg::Clock>("/x");
  EXPECT_THROW(bus.subscribe<msg::Imu>("/x", [](const msg::Imu&) {}), std::logic_error);
}

// A plant on its own bus, with a test probe that plays the controller.
struct PlantRig {
  InProcessTransport bus;
  Topics topics = Topics::for_namespace("/drone");
  model::VehicleParams vehicle;
  std::vector<msg::PoseStamped> poses;
  std::vector<msg::Imu> imus;
  std::vector<msg::Clock> clocks;
  Publisher<msg::Float64MultiArray> cmd;
  std::unique_ptr<PlantNode> plant;

  explicit PlantRig(PlantOptions opt = {}, model::State x0 = {}) {
    bus.subscribe<msg::PoseStamped>(topics.pose, [this](const msg::PoseStamped& m) { poses.push_back(m); });
    bus.subscribe<msg::Imu>(topics.imu, [this](const msg::Imu& m) { imus.push_back(m); });
    bus.subscribe<msg::Clock>(topics.clock, [this](const msg::Clock& m) { clocks.push_back(m); });
    cmd = bus.advertise<msg::Float64MultiArray>(topics.motor_commands);
    plant = std::make_unique<PlantNode>(bus, topics, vehicle, opt, x0);
  }
  void send(std::vector<double> w) {
    msg::Float64MultiArray m;
    m.data = std::move(w);
    cmd.publish(m);
  }
};

TEST(PlantNodeTest, PublishesStampedOutputsOfTheState) {
  model::State x0;
  x0.p_W = {1.0, 2.0, 3.0};
  PlantRig rig({}, x0);
  rig.plant->publish_outputs(7);
  ASSERT_EQ(rig.poses.size(), 1u);
  EXPECT_EQ(rig.poses[0].header.stamp.to_ns(), 70'000'000);
  EXPECT_EQ(rig.clocks[0].clock.to_ns(), 70'000'000);
  EXPECT_EQ(rig.poses[0].position.x, 1.0);
  EXPECT_EQ(rig.poses[0].position.z, 3.0);
  EXPECT_EQ(rig.poses[0].orientation.w, 1.0);
  // Airborne with rotors stopped: the accelerometer reads free fall, zero.
  EXPECT_NEAR(rig.imus[0].linear_acceleration.z, 0.0, 1e-12);
}

TEST(PlantNodeTest, RejectsMalformedCommandsAndHoldsTheLastGoodOne) {
  PlantRig rig;
  rig.plant->publish_outputs(0);
  rig.send({100, 200, 300, 400});
  rig.send({1, 2, 3});                // wrong length
  rig.send({});                       // empty
  rig.send({1, std::nan(""), 3, 4});  // NaN
  rig.send({1, 2, INFINITY, 4});      // Inf
  rig.plant->latch_command(0);
  EXPECT_EQ(rig.plant->stats().commands_received, 5u);
  EXPECT_EQ(rig.plant->stats().commands_rejected, 4u);
  EXPECT_EQ(rig.plant->latched_command(), model::Vector4(100, 200, 300, 400));
}

TEST(PlantNodeTest, OutOfRangeCommandsAreClampedByTheModel) {
  model::State x0;
  x0.p_W.z() = 50.0;
  PlantRig rig({}, x0);
  rig.plant->publish_outputs(0);
  rig.send({-5.0, 1e9, 0.0, 0.0});
  rig.plant->latch_command(0);
  rig.plant->integrate(0);
  EXPECT_EQ(rig.plant->state().omega_rad_s[0], rig.vehicle.motor.omega_min_rad_s);
  EXPECT_EQ(rig.plant->state().omega_rad_s[1], rig.vehicle.motor.omega_max_rad_s);
  EXPECT_TRUE(rig.plant->state().p_W.allFinite());
}

TEST(PlantNodeTest, CommandDelayShiftsTheEffectByWholeTicks) {
  PlantOptions opt;
  opt.command_delay_ticks = 3;
  PlantRig rig(opt);
  rig.plant->publish_outputs(10);
  rig.send({1, 1, 1, 1});
  for (Tick k = 10; k < 13; ++k) {
    rig.plant->latch_command(k);
    EXPECT_EQ(rig.plant->latched_command(), model::Vector4::Zero()) << "tick " << k;
  }
  rig.plant->latch_command(13);
  EXPECT_EQ(rig.plant->latched_command(), model::Vector4::Ones());
}

TEST(ControllerNodeTest, PublishesTheSafetyCommandUntilSensorsArrive) {
  InProcessTransport bus;
  const Topics topics = Topics::for_namespace("/drone");
  std::vector<msg::Float64MultiArray> out;
  bus.subscribe<msg::Float64MultiArray>(topics.motor_commands,
                                        [&](const msg::Float64MultiArray& m) { out.push_back(m); });
  control::ControllerConfig cfg;
  cfg.params.safety = control::SafetyMode::kHover;
  ControllerNode node(bus, topics, cfg);
  const auto& c = node.step(0, 0.02);
  EXPECT_TRUE(c.safety);
  ASSERT_EQ(out.size(), 1u);
  ASSERT_EQ(out[0].data.size(), 4u);
  const double hover = std::sqrt(1.96 * 9.81 / (4 * 2.06e-7));
  for (double w : out[0].data) EXPECT_NEAR(w, hover, 1e-9);
}

TEST(ControllerNodeTest, GoesToSafetyWhenDataGetsStaleAndRecovers) {
  InProcessTransport bus;
  const Topics topics = Topics::for_namespace("/drone");
  control::ControllerConfig cfg;
  cfg.params.stale_limit_s = 0.1;
  cfg.setpoint.p_des_W.z() = 5.0;
  ControllerNode node(bus, topics, cfg);
  model::State x0;
  x0.p_W.z() = 5.0;
  PlantNode plant(bus, topics, cfg.params.vehicle, {}, x0);

  plant.publish_outputs(0);  // data stamped t = 0
  EXPECT_FALSE(node.step(0, 0.02).safety);
  EXPECT_FALSE(node.step(100'000'000, 0.02).safety);  // exactly at the limit: still fresh
  EXPECT_TRUE(node.step(120'000'000, 0.02).safety);   // 0.12 s old
  plant.publish_outputs(12);                          // fresh data at t = 0.12 s
  EXPECT_FALSE(node.step(120'000'000, 0.02).safety);
}

TEST(ControllerNodeTest, ParameterChangesAreCheckedAndAppliedBetweenSteps) {
  InProcessTransport bus;
  ControllerNode node(bus, Topics::for_namespace("/drone"), {});
  EXPECT_EQ(node.set_parameter("z_des", 10.0), "");
  EXPECT_EQ(node.config().setpoint.p_des_W.z(), 10.0);
  EXPECT_NE(node.set_parameter("z_des", std::nan("")), "");
  EXPECT_EQ(node.config().setpoint.p_des_W.z(), 10.0);
  EXPECT_NE(node.set_parameter("no_such", 1.0), "");
  const double k_before = node.controller().axis(0).K(0);
  EXPECT_EQ(node.set_parameter("lqr.roll.q_angle", 10.0), "");
  EXPECT_NE(node.controller().axis(0).K(0), k_before);  // the LQR was re-solved
}

// A short run of the full loop with a recorder that keeps everything it saw.
struct Recorded {
  std::vector<double> t, z, cmd0;
  std::vector<model::State> states;
  std::vector<model::Vector4> applied;
};

Recorded run(const SimulationConfig& cfg, std::vector<ScheduledParameter> schedule, model::State x0 = {}) {
  control::ControllerConfig controller;
  Simulation s(cfg, controller.params.vehicle, x0, controller, std::move(schedule));
  Recorded r;
  s.run([&](const TickRecord& rec) {
    r.t.push_back(rec.t_s);
    r.z.push_back(rec.state.p_W.z());
    r.states.push_back(rec.state);
    r.applied.push_back(rec.latched_command);
  });
  return r;
}

TEST(SimulationTest, RecordsEveryTickFromZeroToTheEnd) {
  SimulationConfig cfg;
  cfg.duration_ticks = 200;
  const Recorded r = run(cfg, {{0, "z_des", 1.0}});
  ASSERT_EQ(r.t.size(), 201u);
  EXPECT_EQ(r.t.front(), 0.0);
  EXPECT_EQ(r.t.back(), 2.0);
}

TEST(SimulationTest, CommandsChangeOnlyOnControllerTicks) {
  SimulationConfig cfg;
  cfg.duration_ticks = 300;
  cfg.controller_divider = 3;
  const Recorded r = run(cfg, {{0, "z_des", 2.0}});
  int changes = 0;
  for (std::size_t k = 1; k < r.applied.size(); ++k) {
    if (r.applied[k] != r.applied[k - 1]) {
      ++changes;
      EXPECT_EQ(k % 3, 0u) << "command changed between controller ticks at tick " << k;
    }
  }
  EXPECT_GT(changes, 50);
}

TEST(SimulationTest, ScheduledSetpointMakesTheVehicleClimb) {
  SimulationConfig cfg;
  cfg.duration_ticks = 500;
  const Recorded r = run(cfg, {{100, "z_des", 3.0}});
  EXPECT_NEAR(r.z[100], 0.0, 1e-9);  // at the ground (z_des = 0) until the setpoint changes
  EXPECT_GT(r.z.back(), 2.5);
}

TEST(SimulationTest, RefusedScheduledParameterIsAnError) {
  SimulationConfig cfg;
  cfg.duration_ticks = 10;
  control::ControllerConfig controller;
  Simulation s(cfg, controller.params.vehicle, {}, controller, {{5, "roll_des", 9.0}});
  EXPECT_THROW(s.run(nullptr), std::invalid_argument);
}

TEST(SimulationTest, SameInputsGiveTheSameBits) {
  SimulationConfig cfg;
  cfg.duration_ticks = 700;
  std::vector<ScheduledParameter> sched = {{0, "z_des", 4.0}, {300, "roll_des", 0.1}, {400, "yaw_des", 0.3}};
  const Recorded a = run(cfg, sched), b = run(cfg, sched);
  ASSERT_EQ(a.states.size(), b.states.size());
  for (std::size_t k = 0; k < a.states.size(); ++k) {
    const auto& x = a.states[k];
    const auto& y = b.states[k];
    ASSERT_EQ(std::memcmp(x.p_W.data(), y.p_W.data(), sizeof(double) * 3), 0) << k;
    ASSERT_EQ(std::memcmp(x.q_WB.coeffs().data(), y.q_WB.coeffs().data(), sizeof(double) * 4), 0) << k;
    ASSERT_EQ(std::memcmp(x.w_B.data(), y.w_B.data(), sizeof(double) * 3), 0) << k;
  }
}

TEST(SimulationTest, CommandDelayDelaysTheResponse) {
  SimulationConfig cfg;
  cfg.duration_ticks = 100;
  const Recorded prompt = run(cfg, {{0, "z_des", 1.0}});
  cfg.plant.command_delay_ticks = 5;
  const Recorded late = run(cfg, {{0, "z_des", 1.0}});
  // The delayed loop's first thrust command arrives 5 ticks later; before that rotors are stopped.
  EXPECT_GT(prompt.applied[0][0], 0.0);
  for (int k = 0; k < 5; ++k) EXPECT_EQ(late.applied[k][0], 0.0) << k;
  EXPECT_EQ(late.applied[5], prompt.applied[0]);
}

}  // namespace
}  // namespace quadcosim::sim

namespace quadcosim::msg {
namespace {
TEST(CommandLabelTest, WritesAndReadsTheStamp) {
  Float64MultiArray m;
  m.dim = {{"", 4, 4}};
  write_command_label(m.dim[0].label, 123'456'789'012);
  EXPECT_EQ(m.dim[0].label, "rotors@123456789012");
  EXPECT_EQ(command_stamp_ns(m), 123'456'789'012);
  EXPECT_EQ(command_label(0), "rotors@0");
  for (const char* bad :
       {"rotors@", "rotors@-5", "rotors@+5", "rotors@12x", "rotors@99999999999999999999", "rotor@5", "", "rotors@ 5"}) {
    m.dim[0].label = bad;
    EXPECT_EQ(command_stamp_ns(m), -1) << bad;
  }
  m.dim[0].label = "rotors@9223372036854775799";
  EXPECT_EQ(command_stamp_ns(m), 9223372036854775799);
  EXPECT_EQ(command_label(-20), "rotors@-20");
  EXPECT_EQ(command_label(INT64_MIN), "rotors@-9223372036854775808");
}

TEST(CommandLabelTest, AgreesWithStdToStringAtEveryLength) {
  // Every digit count and the edges between them, written and read back, against std::to_string.
  std::vector<std::int64_t> values = {0, INT64_MAX, INT64_MIN, -1};
  std::int64_t p = 1;
  for (int e = 0; e <= 18; ++e) {  // p = 10^e
    if (e > 0) p *= 10;
    for (std::int64_t v : {p - 1, p, p + 1, 7 * p + 3, -p}) values.push_back(v);
  }
  Float64MultiArray m;
  m.dim = {{"", 4, 4}};
  for (std::int64_t v : values) {
    write_command_label(m.dim[0].label, v);
    EXPECT_EQ(m.dim[0].label, "rotors@" + std::to_string(v));
    EXPECT_EQ(command_stamp_ns(m), v >= 0 ? v : -1) << v;
  }
  // A character just outside '0'..'9' at any position of a 17-digit label refuses it.
  for (std::size_t i = 0; i < 17; ++i) {
    for (const char bad : {'/', ':', 'x', ' ', '\0'}) {
      std::string digits = "12345678901234567";
      digits[i] = bad;
      m.dim[0].label = "rotors@" + digits;
      EXPECT_EQ(command_stamp_ns(m), -1) << i << " '" << bad << "'";
    }
  }
}
}  // namespace
}  // namespace quadcosim::msg
