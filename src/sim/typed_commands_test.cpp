// The typed command topics (/<ns>/cmd/<level>, sim/level_messages.hpp) on the plant's one intake: a
// typed command flies exactly as the same values named by a layout label on motor_commands, and it is
// checked, counted and named the same way; one topic commands a tick.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <limits>
#include <memory>
#include <numbers>
#include <string>
#include <vector>

#include "model/attitude.hpp"
#include "sim/inprocess_transport.hpp"
#include "sim/level_messages.hpp"
#include "sim/message_schema.hpp"
#include "sim/plant_node.hpp"
#include "sim/plant_rig_test_support.hpp"
#include "sim/topics.hpp"

namespace quadcosim::sim {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

// A plant hovering at z_m without a watchdog, with a publisher on motor_commands and on four of the
// typed topics.
struct TypedRig : test::PlantRig {
  Publisher<msg::ThrustRates> ctbr = level_publisher<msg::ThrustRates>(control::CommandLevel::kCtbr);
  Publisher<msg::RotorThrusts> thrusts = level_publisher<msg::RotorThrusts>(control::CommandLevel::kRotorThrusts);
  Publisher<msg::ThrustAttitude> ctatt = level_publisher<msg::ThrustAttitude>(control::CommandLevel::kCtatt);
  Publisher<msg::VelocityYaw> velocity = level_publisher<msg::VelocityYaw>(control::CommandLevel::kVelocity);

  explicit TypedRig(PlantOptions options = {}, double z_m = 10.0)
      : PlantRig(without_watchdog(options),
                 model::Quadrotor(model::VehicleParams{}).initial_state({0.0, 0.0, z_m}, 0.0, true)) {}
  void tick(Tick k) { latch_and_integrate(k); }
};

TEST(TypedCommands, TopicsAreNamedAfterTheLevels) {
  const Topics t = Topics::for_namespace("/uav1");
  EXPECT_EQ(t.level_commands[0], "/uav1/cmd/rotor_speeds");
  EXPECT_EQ(t.level_commands[2], "/uav1/cmd/ctbr");
  EXPECT_EQ(t.level_commands[6], "/uav1/cmd/acceleration");
  EXPECT_EQ(Topics::for_namespace("/").level_commands[3], "/cmd/ctatt");
}

// Each typed message's fields are its level's four values in command_level.hpp's order (setpoint_fields).
TEST(TypedCommands, EachMessageIsItsLevelsFourValuesInOrder) {
  const auto values = [](const msg::LevelValues& v) { return std::vector<double>(v.data(), v.data() + v.count()); };
  msg::RotorSpeeds speeds;
  speeds.omega_rad_s = {1.0, 2.0, 3.0, 4.0};
  EXPECT_EQ(msg::level_values(speeds).level, control::CommandLevel::kRotorSpeeds);
  EXPECT_EQ(values(msg::level_values(speeds)), (std::vector<double>{1.0, 2.0, 3.0, 4.0}));
  msg::RotorThrusts thrusts;
  thrusts.thrust_n = {5.0, 6.0, 7.0};
  EXPECT_EQ(msg::level_values(thrusts).level, control::CommandLevel::kRotorThrusts);
  EXPECT_EQ(values(msg::level_values(thrusts)), (std::vector<double>{5.0, 6.0, 7.0}));  // the length as sent
  msg::ThrustRates rates;
  rates.thrust_n = 19.0;
  rates.body_rates_rad_s = {0.1, 0.2, 0.3};
  EXPECT_EQ(msg::level_values(rates).level, control::CommandLevel::kCtbr);
  EXPECT_EQ(values(msg::level_values(rates)), (std::vector<double>{19.0, 0.1, 0.2, 0.3}));  // U1, p, q, r
  msg::ThrustTorque torque;
  torque.thrust_n = 20.0;
  torque.torque_nm = {0.01, 0.02, 0.03};
  EXPECT_EQ(msg::level_values(torque).level, control::CommandLevel::kCttm);
  EXPECT_EQ(values(msg::level_values(torque)), (std::vector<double>{20.0, 0.01, 0.02, 0.03}));  // U1, U2..U4
  msg::VelocityYaw velocity;
  velocity.velocity_m_s = {1.0, -2.0, 0.5};
  velocity.yaw_rad = 0.7;
  EXPECT_EQ(msg::level_values(velocity).level, control::CommandLevel::kVelocity);
  EXPECT_EQ(values(msg::level_values(velocity)), (std::vector<double>{1.0, -2.0, 0.5, 0.7}));
  msg::AccelerationYaw acceleration;
  acceleration.acceleration_m_s2 = {0.3, 0.2, -0.1};
  acceleration.yaw_rad = -1.0;
  EXPECT_EQ(msg::level_values(acceleration).level, control::CommandLevel::kAcceleration);
  EXPECT_EQ(values(msg::level_values(acceleration)), (std::vector<double>{0.3, 0.2, -0.1, -1.0}));
  // ctatt: U1 and the Z-Y-X angles of the quaternion; a yaw of pi/2 alone is q = (0, 0, sin(pi/4), cos(pi/4)).
  msg::ThrustAttitude attitude;
  attitude.thrust_n = 18.0;
  attitude.attitude = {0.0, 0.0, std::sin(std::numbers::pi / 4.0), std::cos(std::numbers::pi / 4.0)};
  const msg::LevelValues a = msg::level_values(attitude);
  EXPECT_EQ(a.level, control::CommandLevel::kCtatt);
  ASSERT_EQ(a.count(), 4u);
  EXPECT_EQ(a.data()[0], 18.0);
  EXPECT_NEAR(a.data()[1], 0.0, 1e-15);
  EXPECT_NEAR(a.data()[2], 0.0, 1e-15);
  EXPECT_NEAR(a.data()[3], std::numbers::pi / 2.0, 1e-15);
  EXPECT_NEAR(a.attitude_norm, 1.0, 1e-15);
  // The default ThrustAttitude (w = 1, as the .msg default) is level flight.
  EXPECT_EQ(values(msg::level_values(msg::ThrustAttitude{})), (std::vector<double>{0.0, 0.0, 0.0, 0.0}));
}

// The schema text recordings carry for a typed command (the ros2msg convention, written out by hand):
// the fields, then each type they use.
TEST(TypedCommands, RecordingsDescribeTheTypedMessagesAsTheirMsgFiles) {
  EXPECT_EQ(msg::ros2msg_definition("quadcosim_msgs/msg/ThrustAttitude"),
            "std_msgs/Header header\nfloat64 thrust_n\ngeometry_msgs/Quaternion attitude\n"
            "================================================================================\n"
            "MSG: std_msgs/Header\nbuiltin_interfaces/Time stamp\nstring frame_id\n"
            "================================================================================\n"
            "MSG: builtin_interfaces/Time\nint32 sec\nuint32 nanosec\n"
            "================================================================================\n"
            "MSG: geometry_msgs/Quaternion\nfloat64 x 0\nfloat64 y 0\nfloat64 z 0\nfloat64 w 1\n");
  const std::string& v = msg::ros2msg_definition("quadcosim_msgs/msg/VelocityYaw");
  EXPECT_EQ(v.substr(0, v.find("====")),
            "std_msgs/Header header\ngeometry_msgs/Vector3 velocity_m_s\nfloat64 yaw_rad\n");
  const std::string& r = msg::ros2msg_definition("quadcosim_msgs/msg/RotorThrusts");
  EXPECT_EQ(r.substr(0, r.find("====")), "std_msgs/Header header\nfloat64[] thrust_n\n");
}

// ctbr on /drone/cmd/ctbr and the same four values labelled level=ctbr on motor_commands: the same
// states, bit for bit, over 300 ticks of a varying setpoint.
TEST(TypedCommands, ATypedCommandFliesAsTheSameValuesNamedInTheLayout) {
  TypedRig typed, labelled;
  const double hover_n = typed.vehicle.mass_kg * typed.vehicle.gravity_m_s2;
  for (Tick k = 0; k < 300; ++k) {
    typed.plant.publish_outputs(k);
    labelled.plant.publish_outputs(k);
    if (k % 2 == 0) {
      const double t = 0.01 * static_cast<double>(k);
      const double u[4] = {hover_n * (1.0 + 0.05 * std::sin(t)), t < 0.5 ? 0.3 : -0.1, 0.2 * std::cos(3.0 * t), 0.05};
      msg::ThrustRates m;
      m.thrust_n = u[0];
      m.body_rates_rad_s = {u[1], u[2], u[3]};
      typed.ctbr.publish(m);
      msg::Float64MultiArray a;
      a.data.assign(u, u + 4);
      msg::set_command_level(a, "ctbr");
      labelled.cmd.publish(a);
    }
    typed.tick(k);
    labelled.tick(k);
    const model::State& x = typed.plant.state();
    const model::State& y = labelled.plant.state();
    ASSERT_EQ(std::memcmp(x.p_W.data(), y.p_W.data(), sizeof(double) * 3), 0) << "tick " << k;
    ASSERT_EQ(std::memcmp(x.q_WB.coeffs().data(), y.q_WB.coeffs().data(), sizeof(double) * 4), 0) << "tick " << k;
  }
  EXPECT_EQ(typed.plant.core().held().level, control::CommandLevel::kCtbr);
  EXPECT_EQ(typed.plant.stats().commands_accepted, 150u);
  // The rate step turned the vehicle: roll well away from 0.
  EXPECT_GT(std::abs(model::euler_from_quaternion(typed.plant.state().q_WB).roll_rad), 0.05);
}

// The attitude of a ThrustAttitude is held as its Z-Y-X angles (level ctatt's values).
TEST(TypedCommands, AnAttitudeQuaternionIsFlownAsItsEulerAngles) {
  TypedRig rig;
  const model::Euler e{0.1, -0.2, 0.3};
  const Eigen::Quaterniond q = model::quaternion_from_euler(e);
  msg::ThrustAttitude m;
  m.thrust_n = 19.0;
  m.attitude = {q.x(), q.y(), q.z(), q.w()};
  rig.plant.publish_outputs(0);
  rig.ctatt.publish(m);
  rig.tick(0);
  const control::LevelCommand& held = rig.plant.core().held();
  ASSERT_EQ(held.level, control::CommandLevel::kCtatt);
  EXPECT_EQ(held.value[0], 19.0);
  EXPECT_NEAR(held.value[1], 0.1, 1e-12);
  EXPECT_NEAR(held.value[2], -0.2, 1e-12);
  EXPECT_NEAR(held.value[3], 0.3, 1e-12);
}

// NaN, a wrong length and a quaternion that is not a unit one: rejected, counted, named; a second topic
// in one tick: refused, counted, named, and the first topic's command is the one flown.
TEST(TypedCommands, BadTypedCommandsAndASecondTopicInOneTickAreRefusedByName) {
  TypedRig rig;
  rig.plant.publish_outputs(0);
  msg::ThrustRates nan_rates;
  nan_rates.thrust_n = 19.0;
  nan_rates.body_rates_rad_s = {0.0, kNaN, 0.0};
  rig.ctbr.publish(nan_rates);
  EXPECT_EQ(rig.plant.stats().last_problem, "ctbr value 3 (q [rad/s]) is nan, expected a finite number");
  rig.tick(0);

  rig.plant.publish_outputs(1);
  msg::RotorThrusts three;
  three.thrust_n = {4.0, 4.0, 4.0};
  rig.thrusts.publish(three);
  EXPECT_EQ(rig.plant.stats().last_problem, "3 values, expected 4 for level rotor_thrusts");
  rig.tick(1);

  rig.plant.publish_outputs(2);
  msg::ThrustAttitude half;
  half.thrust_n = 19.0;
  half.attitude = {0.0, 0.0, 0.0, 0.5};
  rig.ctatt.publish(half);
  EXPECT_EQ(rig.plant.stats().last_problem, "ctatt attitude has norm 0.5, expected a unit quaternion (x, y, z, w)");
  rig.tick(2);

  rig.plant.publish_outputs(3);
  msg::VelocityYaw up;
  up.velocity_m_s = {0.0, 0.0, 1.0};
  rig.velocity.publish(up);  // answers tick 3
  msg::ThrustRates rates;
  rates.thrust_n = 30.0;
  rig.ctbr.publish(rates);  // a second topic in the same tick
  msg::Float64MultiArray speeds;
  speeds.data = {100.0, 100.0, 100.0, 100.0};
  rig.cmd.publish(speeds);  // and a third
  EXPECT_EQ(rig.plant.stats().last_problem,
            "a command on /drone/motor_commands for the tick (t = 0.03 s) that /drone/cmd/velocity already "
            "commanded: one topic commands a tick");
  rig.tick(3);
  EXPECT_EQ(rig.plant.core().held().level, control::CommandLevel::kVelocity);
  // The next tick another topic may command.
  rig.plant.publish_outputs(4);
  rig.ctbr.publish(rates);
  rig.tick(4);
  EXPECT_EQ(rig.plant.core().held().level, control::CommandLevel::kCtbr);

  const PlantStats& st = rig.plant.stats();
  EXPECT_EQ(st.commands_received, 5u);  // the three bad ones, velocity, ctbr; not the two refused
  EXPECT_EQ(st.commands_rejected, 3u);
  EXPECT_EQ(st.commands_rejected_non_finite, 1u);
  EXPECT_EQ(st.commands_rejected_length, 1u);
  EXPECT_EQ(st.commands_rejected_bad_quaternion, 1u);
  EXPECT_EQ(st.commands_rejected_second_topic, 2u);
  EXPECT_EQ(st.commands_accepted, 2u);
  ASSERT_EQ(rig.log.size(), 2u);  // each kind's 1st (then every 100th)
  EXPECT_EQ(rig.log[0],
            "plant: command on /drone/cmd/ctbr rejected (ctbr value 3 (q [rad/s]) is nan, expected a finite "
            "number), last good command held; 1 rejected so far (logged: 1st, then every 100th)");
  EXPECT_EQ(rig.log[1],
            "plant: a command on /drone/cmd/ctbr for the tick (t = 0.03 s) that /drone/cmd/velocity already "
            "commanded: one topic commands a tick; ignored, 1 so far (logged: 1st, then every 100th)");
  // The counts go out in the plant status.
  rig.plant.publish_outputs(5);
  ASSERT_FALSE(rig.statuses.empty());
  EXPECT_EQ(rig.statuses.back().commands_rejected_second_topic, 2u);
  EXPECT_EQ(rig.statuses.back().commands_rejected_bad_quaternion, 1u);
}

// Lockstep: header.stamp is the label. A second topic answering the same stamp later (after the tick
// moved on) is refused as a second writer, not taken as an answer; a repeat on the same topic is stale.
TEST(TypedCommands, InLockstepTheStampIsTheLabelAndASecondTopicForItIsRefused) {
  PlantOptions o;
  o.drop_stale_commands = true;
  TypedRig rig(o);
  rig.plant.publish_outputs(0);
  msg::ThrustRates rates;
  rates.thrust_n = 19.0;
  rates.header.stamp = msg::Time::from_ns(0);
  rig.ctbr.publish(rates);
  EXPECT_EQ(rig.plant.command_receipt().label_ns, 0);
  rig.tick(0);
  rig.plant.publish_outputs(1);
  rig.ctbr.publish(rates);  // a repeat of tick 0's answer
  msg::VelocityYaw v;
  v.header.stamp = msg::Time::from_ns(0);
  rig.velocity.publish(v);  // tick 0 again, from another topic
  rig.tick(1);
  rig.plant.publish_outputs(2);
  rates.header.stamp = msg::Time::from_ns(20'000'000);
  rig.ctbr.publish(rates);
  EXPECT_EQ(rig.plant.command_receipt().label_ns, 20'000'000);
  const PlantStats& st = rig.plant.stats();
  EXPECT_EQ(st.commands_stale, 1u);
  EXPECT_EQ(st.commands_rejected_second_topic, 1u);
  EXPECT_EQ(st.commands_accepted, 2u);
  EXPECT_EQ(st.last_problem,
            "a command on /drone/cmd/velocity for the tick (t = 0 s) that /drone/cmd/ctbr already commanded: one "
            "topic commands a tick");
}

}  // namespace
}  // namespace quadcosim::sim
