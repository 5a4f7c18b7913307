// Tests of the co-simulation layer: transport, nodes, the multi-rate scheduler, determinism.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <limits>
#include <memory>
#include <string>
#include <vector>

#include "controllers/paper/paper_controller.hpp"
#include "controllers/registry.hpp"
#include "sim/controller_node.hpp"
#include "sim/inprocess_transport.hpp"
#include "sim/plant_node.hpp"
#include "sim/plant_rig_test_support.hpp"
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

// A plant on its own bus (its options as given), with a test probe that plays the controller and
// collects the poses, IMU samples and clock messages.
struct ProbeRig : test::PlantRig {
  std::vector<msg::PoseStamped> poses;
  std::vector<msg::Imu> imus;
  std::vector<msg::Clock> clocks;

  explicit ProbeRig(const PlantOptions& opt = {}, const model::State& x0 = {}) : PlantRig(opt, x0) {
    bus.subscribe<msg::PoseStamped>(topics.pose, [this](const msg::PoseStamped& m) { poses.push_back(m); });
    bus.subscribe<msg::Imu>(topics.imu, [this](const msg::Imu& m) { imus.push_back(m); });
    bus.subscribe<msg::Clock>(topics.clock, [this](const msg::Clock& m) { clocks.push_back(m); });
  }
};

TEST(PlantNodeTest, PublishesStampedOutputsOfTheState) {
  model::State x0;
  x0.p_W = {1.0, 2.0, 3.0};
  ProbeRig rig({}, x0);
  rig.plant.publish_outputs(7);
  ASSERT_EQ(rig.poses.size(), 1u);
  EXPECT_EQ(rig.poses[0].header.stamp.to_ns(), 70'000'000);
  EXPECT_EQ(rig.clocks[0].clock.to_ns(), 70'000'000);
  EXPECT_EQ(rig.poses[0].position.x, 1.0);
  EXPECT_EQ(rig.poses[0].position.z, 3.0);
  EXPECT_EQ(rig.poses[0].orientation.w, 1.0);
  // Airborne with rotors stopped: the accelerometer reads free fall, zero.
  EXPECT_NEAR(rig.imus[0].linear_acceleration.z, 0.0, 1e-12);
}

// The order of a tick's messages: /clock first by default; last with clock_after_sensors, so a peer
// that steps when /clock arrives holds the tick's samples by then (docs/simulink.md).
TEST(PlantNodeTest, PublishesClockBeforeOrAfterTheSensors) {
  for (const bool after : {false, true}) {
    InProcessTransport bus;
    const Topics topics = Topics::for_namespace("/drone");
    std::vector<std::string> order;
    bus.subscribe<msg::Clock>(topics.clock, [&](const msg::Clock&) { order.push_back("clock"); });
    bus.subscribe<msg::PoseStamped>(topics.pose, [&](const msg::PoseStamped&) { order.push_back("pose"); });
    bus.subscribe<msg::TwistStamped>(topics.velocity, [&](const msg::TwistStamped&) { order.push_back("velocity"); });
    bus.subscribe<msg::Imu>(topics.imu, [&](const msg::Imu&) { order.push_back("imu"); });
    PlantOptions opt;
    opt.clock_after_sensors = after;
    PlantNode plant(bus, topics, model::VehicleParams{}, opt, model::State{});
    plant.publish_outputs(2);
    const std::vector<std::string> expected = after ? std::vector<std::string>{"pose", "velocity", "imu", "clock"}
                                                    : std::vector<std::string>{"clock", "pose", "velocity", "imu"};
    EXPECT_EQ(order, expected) << "clock_after_sensors = " << after;
  }
}

TEST(PlantNodeTest, RejectsMalformedCommandsAndHoldsTheLastGoodOne) {
  ProbeRig rig;
  rig.plant.publish_outputs(0);
  rig.send({100, 200, 300, 400});
  rig.send({1, 2, 3});                // wrong length
  rig.send({});                       // empty
  rig.send({1, std::nan(""), 3, 4});  // NaN
  rig.send({1, 2, INFINITY, 4});      // Inf
  rig.plant.latch_command(0);
  EXPECT_EQ(rig.plant.stats().commands_received, 5u);
  EXPECT_EQ(rig.plant.stats().commands_rejected, 4u);
  EXPECT_EQ(rig.plant.latched_command(), model::Vector4(100, 200, 300, 400));
}

TEST(PlantNodeTest, OutOfRangeCommandsAreClampedByTheModel) {
  model::State x0;
  x0.p_W.z() = 50.0;
  ProbeRig rig({}, x0);
  rig.plant.publish_outputs(0);
  rig.send({-5.0, 1e9, 0.0, 0.0});
  rig.plant.latch_command(0);
  rig.plant.integrate(0);
  EXPECT_EQ(rig.plant.state().omega_rad_s[0], rig.vehicle.motor.omega_min_rad_s);
  EXPECT_EQ(rig.plant.state().omega_rad_s[1], rig.vehicle.motor.omega_max_rad_s);
  EXPECT_TRUE(rig.plant.state().p_W.allFinite());
}

TEST(PlantNodeTest, CommandDelayShiftsTheEffectByWholeTicks) {
  PlantOptions opt;
  opt.command_delay_ticks = 3;
  ProbeRig rig(opt);
  rig.plant.publish_outputs(10);
  rig.send({1, 1, 1, 1});
  for (Tick k = 10; k < 13; ++k) {
    rig.plant.latch_command(k);
    EXPECT_EQ(rig.plant.latched_command(), model::Vector4::Zero()) << "tick " << k;
  }
  rig.plant.latch_command(13);
  EXPECT_EQ(rig.plant.latched_command(), model::Vector4::Ones());
}

TEST(ControllerNodeTest, PublishesTheSafetyCommandUntilSensorsArrive) {
  InProcessTransport bus;
  const Topics topics = Topics::for_namespace("/drone");
  std::vector<msg::Float64MultiArray> out;
  bus.subscribe<msg::Float64MultiArray>(topics.motor_commands,
                                        [&](const msg::Float64MultiArray& m) { out.push_back(m); });
  control::ControllerConfig cfg = controllers::make_config("paper", model::VehicleParams{});
  cfg.node.safety = control::SafetyMode::kHover;
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
  control::ControllerConfig cfg = controllers::make_config("paper", model::VehicleParams{});
  cfg.node.stale_limit_s = 0.1;
  cfg.node.setpoint.p_des_W.z() = 5.0;
  ControllerNode node(bus, topics, cfg);
  model::State x0;
  x0.p_W.z() = 5.0;
  PlantNode plant(bus, topics, cfg.vehicle, {}, x0);

  plant.publish_outputs(0);  // data stamped t = 0
  EXPECT_FALSE(node.step(0, 0.02).safety);
  EXPECT_FALSE(node.step(100'000'000, 0.02).safety);  // exactly at the limit: still fresh
  EXPECT_TRUE(node.step(120'000'000, 0.02).safety);   // 0.12 s old
  plant.publish_outputs(12);                          // fresh data at t = 0.12 s
  EXPECT_FALSE(node.step(120'000'000, 0.02).safety);
}

TEST(ControllerNodeTest, ParameterChangesAreCheckedAndAppliedBetweenSteps) {
  InProcessTransport bus;
  ControllerNode node(bus, Topics::for_namespace("/drone"), controllers::make_config("paper", model::VehicleParams{}));
  EXPECT_EQ(node.set_parameter("z_des", 10.0), "");
  EXPECT_EQ(node.settings().setpoint.p_des_W.z(), 10.0);
  EXPECT_NE(node.set_parameter("z_des", std::nan("")), "");
  EXPECT_EQ(node.settings().setpoint.p_des_W.z(), 10.0);
  EXPECT_NE(node.set_parameter("no_such", 1.0), "");
  const auto& paper = dynamic_cast<const controllers::PaperController&>(node.controller());
  const double k_before = paper.axis(0).K(0);
  EXPECT_EQ(node.set_parameter("lqr.roll.q_angle", 10.0), "");
  EXPECT_NE(paper.axis(0).K(0), k_before);  // the LQR was re-solved
}

// The stale-data safety of Algorithm 1 (lines 3-5) is the node's, for every controller: a controller
// node fed by the test, which publishes Pose, Velocity and Imu samples itself.
struct SensorFeed {
  InProcessTransport bus;
  Topics topics = Topics::for_namespace("/drone");
  Publisher<msg::PoseStamped> pose = bus.advertise<msg::PoseStamped>(topics.pose);
  Publisher<msg::TwistStamped> velocity = bus.advertise<msg::TwistStamped>(topics.velocity);
  Publisher<msg::Imu> imu = bus.advertise<msg::Imu>(topics.imu);
  std::unique_ptr<ControllerNode> node;

  explicit SensorFeed(const control::ControllerConfig& cfg) {
    node = std::make_unique<ControllerNode>(bus, topics, cfg);
    node->set_log([](const std::string&) {});
  }
  // A level vehicle at rest at height z, stamped `ns`; `bad` (0..12) puts `value` in one field: 0-2
  // position, 3-5 velocity, 6-8 body rates, 9-12 the Imu quaternion (w, x, y, z); -1: none.
  void send(std::int64_t ns, double z, int bad = -1, double value = 0.0, bool with_imu = true) {
    msg::PoseStamped p;
    p.header.stamp = msg::Time::from_ns(ns);
    p.position.z = z;
    p.orientation.w = 1.0;
    msg::TwistStamped v;
    v.header.stamp = p.header.stamp;
    msg::Imu i;
    i.header.stamp = p.header.stamp;
    i.orientation.w = 1.0;
    i.linear_acceleration.z = 9.81;
    double* fields[] = {&p.position.x,         &p.position.y,    &p.position.z,         &v.linear.x,
                        &v.linear.y,           &v.linear.z,      &i.angular_velocity.x, &i.angular_velocity.y,
                        &i.angular_velocity.z, &i.orientation.w, &i.orientation.x,      &i.orientation.y,
                        &i.orientation.z};
    if (bad >= 0) *fields[bad] = value;
    pose.publish(p);
    velocity.publish(v);
    if (with_imu) imu.publish(i);
  }
};

// sqrt(m g / (4 kt)) from Table 1 (~4830.6 rad/s).
const double kHoverSpeed = std::sqrt(1.96 * 9.81 / (4 * 2.06e-7));

TEST(ControllerNodeSafetyTest, StaleOrMissingDataGivesTheSafetyCommand) {
  model::VehicleParams vehicle;
  vehicle.motor.omega_min_rad_s = 350.0;
  control::ControllerConfig cfg = controllers::make_config("paper", vehicle);
  cfg.node.setpoint.p_des_W.z() = 5.0;
  ASSERT_EQ(cfg.node.stale_limit_s, 0.1);
  ASSERT_EQ(cfg.node.safety, control::SafetyMode::kStop);
  {
    SensorFeed feed(cfg);
    // Nothing received yet: infinitely old.
    const control::ControllerOutput& c = feed.node->step(0, 0.02);
    EXPECT_TRUE(c.safety);
    EXPECT_TRUE(std::isinf(feed.node->observation().age_s));
    EXPECT_EQ(c.omega_rad_s, Eigen::Vector4d::Constant(350.0));
  }
  constexpr std::int64_t t0 = 1'000'000'000;
  for (std::int64_t age_ns : {100'000'001LL, 200'000'000LL, 10'000'000'000LL}) {
    SCOPED_TRACE(testing::Message() << "age " << age_ns << " ns");
    SensorFeed feed(cfg);
    feed.send(t0, 5.0);
    ASSERT_FALSE(feed.node->step(t0, 0.02).safety);
    const control::ControllerOutput& c = feed.node->step(t0 + age_ns, 0.02);
    EXPECT_TRUE(c.safety);
    EXPECT_TRUE(feed.node->status().safety);
    EXPECT_EQ(c.omega_rad_s, Eigen::Vector4d::Constant(350.0));
  }
  {
    // At the limit the data still counts as fresh.
    SensorFeed feed(cfg);
    feed.send(t0, 5.0);
    EXPECT_FALSE(feed.node->step(t0 + 100'000'000, 0.02).safety);
    EXPECT_EQ(feed.node->observation().age_s, 0.1);
  }
  {
    // One input that never arrived (no Imu) makes the whole observation infinitely old.
    SensorFeed feed(cfg);
    feed.send(t0, 5.0, -1, 0.0, /*with_imu=*/false);
    const control::ControllerOutput& c = feed.node->step(t0, 0.02);
    EXPECT_TRUE(c.safety);
    EXPECT_TRUE(std::isinf(feed.node->observation().age_s));
    EXPECT_EQ(c.omega_rad_s, Eigen::Vector4d::Constant(350.0));
  }
}

TEST(ControllerNodeSafetyTest, SafetyStopIsOmegaMinAndSafetyHoverIsHoverSpeed) {
  control::ControllerConfig cfg = controllers::make_config("paper", model::VehicleParams{});
  cfg.node.setpoint.p_des_W.z() = 5.0;
  ASSERT_EQ(cfg.node.safety, control::SafetyMode::kStop);
  ASSERT_EQ(cfg.vehicle.motor.omega_min_rad_s, 0.0);
  {
    SensorFeed feed(cfg);
    feed.send(0, 5.0);
    const control::ControllerOutput& c = feed.node->step(1'000'000'000, 0.02);  // 1 s old
    EXPECT_TRUE(c.safety);
    EXPECT_EQ(c.omega_rad_s, Eigen::Vector4d::Zero());
  }
  {
    SensorFeed feed(cfg);
    ASSERT_EQ(feed.node->set_parameter("safety_mode", std::string("hover")), "");
    feed.send(0, 5.0);
    const control::ControllerOutput& c = feed.node->step(1'000'000'000, 0.02);
    EXPECT_TRUE(c.safety);
    for (int i = 0; i < 4; ++i) EXPECT_NEAR(c.omega_rad_s[i], kHoverSpeed, 1e-9 * kHoverSpeed);
  }
}

// A non-finite sample never reaches the controller: the node refuses it, the observation keeps its
// last valid values and ages, and once older than stale_limit the safety command goes out while the
// controller (and its integrator) is left alone.
TEST(ControllerNodeSafetyTest, NonFiniteSamplesGiveSafetyAndLeaveTheIntegratorAlone) {
  control::ControllerConfig cfg = controllers::make_config("paper", model::VehicleParams{});
  cfg.node.setpoint.mode = control::Mode::kPosition;
  cfg.node.setpoint.p_des_W = {1.0, 0.0, 5.0};
  SensorFeed feed(cfg);
  const auto& paper = dynamic_cast<const controllers::PaperController&>(feed.node->controller());
  std::int64_t t = 0;
  constexpr std::int64_t kPeriod = 20'000'000;
  // Build some integral first.
  for (int i = 0; i < 10; ++i, t += kPeriod) {
    feed.send(t, 5.0);
    ASSERT_FALSE(feed.node->step(t, 0.02).safety);
  }
  ASSERT_GT(paper.position_state().integral_m_s.x(), 0.0);

  std::uint64_t refused = 0;
  for (int field = 0; field < 13; ++field) {
    for (double bad : {std::nan(""), std::numeric_limits<double>::infinity()}) {
      SCOPED_TRACE(testing::Message() << "field " << field << " value " << bad);
      const std::int64_t last_good = t - kPeriod;
      // Up to the limit the controller flies on the last valid sample.
      for (; t - last_good <= 100'000'000; t += kPeriod) {
        feed.send(t, 5.0, field, bad);
        EXPECT_FALSE(feed.node->step(t, 0.02).safety) << "t - last good = " << t - last_good << " ns";
      }
      const Eigen::Vector2d integral = paper.position_state().integral_m_s;
      for (int k = 0; k < 3; ++k, t += kPeriod) {
        feed.send(t, 5.0, field, bad);
        const control::ControllerOutput& c = feed.node->step(t, 0.02);
        EXPECT_TRUE(c.safety);
        EXPECT_TRUE(c.omega_rad_s.allFinite());
        EXPECT_EQ(c.omega_rad_s, Eigen::Vector4d::Zero());
        EXPECT_EQ(paper.position_state().integral_m_s, integral);
        EXPECT_TRUE(feed.node->observation().p_W.allFinite());
        EXPECT_TRUE(feed.node->observation().v_W.allFinite());
        EXPECT_TRUE(feed.node->observation().w_B.allFinite());
      }
      refused += 8;  // one message (Pose, Velocity or Imu) per sample, 8 samples
      const msg::ControllerStatus& s = feed.node->status();
      // Every bad message was refused (counted as non-finite, or as a bad quaternion).
      EXPECT_EQ(s.rejected_non_finite + s.rejected_bad_quaternion, refused);
      // And the next good sample is controlled normally.
      feed.send(t, 5.0);
      const control::ControllerOutput& c = feed.node->step(t, 0.02);
      EXPECT_FALSE(c.safety);
      EXPECT_TRUE(c.omega_rad_s.allFinite());
      t += kPeriod;
    }
  }
}

// A short run of the full loop with a recorder that keeps everything it saw.
struct Recorded {
  std::vector<double> t, z, cmd0;
  std::vector<model::State> states;
  std::vector<model::Vector4> applied;
};

Recorded run(const SimulationConfig& cfg, std::vector<ScheduledParameter> schedule, model::State x0 = {}) {
  const control::ControllerConfig controller = controllers::make_config("paper", model::VehicleParams{});
  Simulation s(cfg, controller.vehicle, x0, controller, std::move(schedule));
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

TEST(SimulationTest, OverriddenCommandsReachThePlantInsteadOfTheController) {
  SimulationConfig cfg;
  cfg.duration_ticks = 100;
  const control::ControllerConfig controller = controllers::make_config("paper", model::VehicleParams{});
  Simulation s(cfg, controller.vehicle, {}, controller, {{0, "z_des", 1.0}});
  for (Tick k = 0; k < 10; ++k) s.tick(k);
  const std::int64_t last_step = s.controller().last_step_ns();
  EXPECT_EQ(last_step, cfg.plant.clock.ns(8));
  const model::Vector4 omega(100.0, 200.0, 300.0, 400.0);
  s.override_command(omega);
  for (Tick k = 10; k < 14; ++k) {
    s.tick(k);
    EXPECT_EQ(s.plant().latched_command(), omega) << "tick " << k;
  }
  EXPECT_EQ(s.controller().last_step_ns(), last_step);  // the controller did not step
  s.override_command(std::nullopt);
  s.tick(14);
  EXPECT_EQ(s.controller().last_step_ns(), cfg.plant.clock.ns(14));
  EXPECT_NE(s.plant().latched_command(), omega);
}

TEST(SimulationTest, RefusedScheduledParameterIsAnError) {
  SimulationConfig cfg;
  cfg.duration_ticks = 10;
  const control::ControllerConfig controller = controllers::make_config("paper", model::VehicleParams{});
  Simulation s(cfg, controller.vehicle, {}, controller, {{5, "roll_des", 9.0}});
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
