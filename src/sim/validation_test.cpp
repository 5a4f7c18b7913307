// Tests of the checks on incoming messages (sim/validation.hpp) and of how the plant and the
// controller count, log and survive what they refuse.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <string>
#include <vector>

#include "sim/controller_node.hpp"
#include "sim/inprocess_transport.hpp"
#include "sim/plant_node.hpp"
#include "sim/validation.hpp"

namespace quadcosim::sim {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
constexpr double kInf = std::numeric_limits<double>::infinity();
constexpr std::int64_t kNever = std::numeric_limits<std::int64_t>::min();

msg::Float64MultiArray command(std::vector<double> w) {
  msg::Float64MultiArray m;
  m.data = std::move(w);
  return m;
}

TEST(ValidateCommandTest, FourFiniteSpeedsInRangeAreUsedAsSent) {
  const CommandCheck c = validate_command(command({0.0, 1.5, 4830.6, 12000.0}), 12000.0);
  EXPECT_EQ(c.verdict, CommandVerdict::kAccepted);
  EXPECT_EQ(c.omega_rad_s, model::Vector4(0.0, 1.5, 4830.6, 12000.0));
  EXPECT_EQ(c.reason, "");
}

TEST(ValidateCommandTest, TheQuickCheckAcceptsExactlyWhatTheFullCheckAcceptsAsSent) {
  const double kInfinity = std::numeric_limits<double>::infinity();
  const double kNotANumber = std::numeric_limits<double>::quiet_NaN();
  const std::vector<double> speeds = {0.0, -0.0, 1e-300, -1e-300, 4830.6, 12000.0, std::nextafter(12000.0, 1e9),
                                      -5.0, 1e9, kInfinity, -kInfinity, kNotANumber};
  int accepted = 0;
  for (const double a : speeds) {
    for (const double b : speeds) {
      for (const std::vector<double>& d : {std::vector<double>{a, 100.0, b, 200.0}, std::vector<double>{b, a, 3.0, 4.0},
                                           std::vector<double>{a, b, 1.0}, std::vector<double>{a, b, 1.0, 2.0, 3.0}}) {
        const CommandCheck full = validate_command(command(d), 12000.0);
        const bool quick = command_ok(command(d), 12000.0);
        EXPECT_EQ(quick, full.verdict == CommandVerdict::kAccepted) << d.size() << " values, " << a << ", " << b;
        accepted += quick;
      }
    }
  }
  EXPECT_EQ(accepted, 2 * 5 * 5);  // 0, -0, 1e-300, 4830.6, 12000 paired, in the two four-value layouts
}

TEST(ValidateCommandTest, WrongLengthAndNonFiniteAreRejectedWithTheReason) {
  struct Case {
    std::vector<double> data;
    std::string reason;
  };
  const std::vector<Case> cases = {
      {{}, "0 values, expected 4 rotor speeds"},
      {{1, 2, 3}, "3 values, expected 4 rotor speeds"},
      {{1, 2, 3, 4, 5}, "5 values, expected 4 rotor speeds"},
      {{1, kNaN, 3, 4}, "rotor 2 speed is nan, expected a finite number"},
      {{1, 2, 3, kInf}, "rotor 4 speed is inf, expected a finite number"},
      {{-kInf, 2, 3, 4}, "rotor 1 speed is -inf, expected a finite number"},
  };
  for (const auto& c : cases) {
    const CommandCheck r = validate_command(command(c.data), 12000.0);
    EXPECT_EQ(r.verdict, CommandVerdict::kRejected) << c.reason;
    EXPECT_EQ(r.reason, c.reason);
  }
}

TEST(ValidateCommandTest, NegativeAndTooFastAreClampedToTheMotorRange) {
  const CommandCheck c = validate_command(command({-5.0, 100.0, 1e9, -1e-300}), 12000.0);
  EXPECT_EQ(c.verdict, CommandVerdict::kClamped);
  EXPECT_EQ(c.omega_rad_s, model::Vector4(0.0, 100.0, 12000.0, 0.0));
  EXPECT_EQ(c.reason, "rotor 1 speed -5 rad/s clamped to 0 (range [0, 12000])");
}

msg::PoseStamped pose_at(std::int64_t ns) {
  msg::PoseStamped m;
  m.header.stamp = msg::Time::from_ns(ns);
  m.position = {1.0, 2.0, 3.0};
  return m;
}

TEST(ValidateSensorTest, PlantOutputsPass) {
  EXPECT_TRUE(validate_pose(pose_at(0), kNever).ok());
  msg::TwistStamped t;
  EXPECT_TRUE(validate_velocity(t, kNever).ok());
  msg::Imu imu;
  imu.orientation = {0.0, 0.0, std::sin(0.5), std::cos(0.5)};  // yaw 1 rad
  EXPECT_TRUE(validate_imu(imu, kNever).ok());
}

TEST(ValidateSensorTest, NonFiniteFieldsAreNamed) {
  msg::PoseStamped p = pose_at(0);
  p.position.y = kNaN;
  SensorCheck c = validate_pose(p, kNever);
  EXPECT_EQ(c.fault, SensorFault::kNonFinite);
  EXPECT_NE(c.reason.find("position"), std::string::npos) << c.reason;
  msg::TwistStamped t;
  t.angular.z = -kInf;
  c = validate_velocity(t, kNever);
  EXPECT_EQ(c.fault, SensorFault::kNonFinite);
  EXPECT_NE(c.reason.find("angular"), std::string::npos) << c.reason;
  msg::Imu imu;
  imu.linear_acceleration.x = kInf;
  EXPECT_EQ(validate_imu(imu, kNever).fault, SensorFault::kNonFinite);
  imu = {};
  imu.orientation.w = kNaN;
  EXPECT_EQ(validate_imu(imu, kNever).fault, SensorFault::kNonFinite);
}

TEST(ValidateSensorTest, QuaternionsMustBeUnitWithinTheStatedTolerance) {
  msg::Imu imu;
  const double tol = kQuaternionNormTolerance;
  auto with_w = [&](double x, double w) {
    imu.orientation = {x, 0.0, 0.0, w};
    return validate_imu(imu, kNever).fault;
  };
  EXPECT_EQ(with_w(0.0, 0.0), SensorFault::kBadQuaternion);  // zero
  EXPECT_EQ(with_w(0.0, 1.0 + 2 * tol), SensorFault::kBadQuaternion);
  EXPECT_EQ(with_w(0.0, 1.0 - 2 * tol), SensorFault::kBadQuaternion);
  EXPECT_EQ(with_w(0.0, 1.0 + 0.5 * tol), SensorFault::kNone);
  EXPECT_EQ(with_w(0.6, 0.8), SensorFault::kNone);        // 0.36 + 0.64 = 1
  EXPECT_EQ(with_w(0.6, 0.6), SensorFault::kBadQuaternion);  // norm 0.849
  msg::PoseStamped p = pose_at(0);
  p.orientation = {0, 0, 0, 0};
  EXPECT_EQ(validate_pose(p, kNever).fault, SensorFault::kBadQuaternion);
}

TEST(ValidateSensorTest, StampsMayRepeatButNotGoBackOrBeMalformed) {
  EXPECT_EQ(validate_pose(pose_at(20'000'000), 20'000'000).fault, SensorFault::kNone);
  EXPECT_EQ(validate_pose(pose_at(10'000'000), 20'000'000).fault, SensorFault::kStampBackwards);
  msg::PoseStamped p = pose_at(0);
  p.header.stamp = {1, 1'000'000'000u};
  EXPECT_EQ(validate_pose(p, kNever).fault, SensorFault::kBadStamp);
  p.header.stamp = {-1, 0};
  EXPECT_EQ(validate_pose(p, kNever).fault, SensorFault::kBadStamp);
}

TEST(LogThrottleTest, LogsTheFirstThenEveryNth) {
  LogThrottle t(100);
  std::vector<std::uint64_t> logged;
  for (int i = 0; i < 250; ++i) {
    if (t.count()) logged.push_back(t.total());
  }
  EXPECT_EQ(logged, (std::vector<std::uint64_t>{1, 101, 201}));
}

// A plant on its own bus; the test plays the controller and watches the plant status.
struct Rig {
  InProcessTransport bus;
  Topics topics = Topics::for_namespace("/drone");
  model::VehicleParams vehicle;
  std::vector<msg::PlantStatus> statuses;
  std::vector<std::string> log;
  Publisher<msg::Float64MultiArray> cmd;
  std::unique_ptr<PlantNode> plant;

  explicit Rig(PlantOptions options = {}) {
    bus.subscribe<msg::PlantStatus>(topics.plant_status, [this](const msg::PlantStatus& m) { statuses.push_back(m); });
    cmd = bus.advertise<msg::Float64MultiArray>(topics.motor_commands);
    model::State x0;
    x0.p_W.z() = 10.0;
    options.watchdog_ticks = 0;  // these ticks go long without commands; the watchdog has its own tests
    plant = std::make_unique<PlantNode>(bus, topics, vehicle, options, x0);
    plant->set_log([this](const std::string& line) { log.push_back(line); });
  }
  void tick(Tick k) {
    plant->publish_outputs(k);
    plant->latch_command(k);
    plant->integrate(k);
  }
};

TEST(PlantValidationTest, StatusCountsRefusedAndClampedCommandsAndGoesOutOnTheNextTick) {
  Rig rig;
  rig.tick(0);
  ASSERT_EQ(rig.statuses.size(), 1u);  // tick 0: the periodic one
  rig.cmd.publish(command({100, 200, 300, 400}));
  rig.tick(1);
  EXPECT_EQ(rig.statuses.size(), 1u) << "nothing refused: no status before the next second";
  rig.cmd.publish(command({1, 2, 3}));
  rig.cmd.publish(command({1, kNaN, 3, 4}));
  rig.cmd.publish(command({-1, 2, 3, 4}));
  rig.tick(2);
  ASSERT_EQ(rig.statuses.size(), 2u);
  const msg::PlantStatus& s = rig.statuses.back();
  EXPECT_EQ(s.header.stamp.to_ns(), 20'000'000);
  EXPECT_EQ(s.commands_accepted, 2u);
  EXPECT_EQ(s.commands_clamped, 1u);
  EXPECT_EQ(s.commands_rejected_length, 1u);
  EXPECT_EQ(s.commands_rejected_non_finite, 1u);
  EXPECT_EQ(s.last_problem, "rotor 1 speed -1 rad/s clamped to 0 (range [0, 12000])");
  EXPECT_EQ(rig.plant->applied_command(), model::Vector4(0, 2, 3, 4));
  for (Tick k = 3; k < 100; ++k) rig.tick(k);
  EXPECT_EQ(rig.statuses.size(), 2u);
  rig.tick(100);
  EXPECT_EQ(rig.statuses.size(), 3u);  // once per simulated second
  EXPECT_EQ(rig.statuses.back().header.stamp.to_ns(), 1'000'000'000);
}

// Lockstep over DDS repeats ticks: the controller then answers the same tick twice. The copies are
// counted apart, so the status counters match an in-process run, which has no repeats.
TEST(PlantValidationTest, LockstepRepeatsOfACommandAreNotCountedTwice) {
  PlantOptions options;
  options.drop_stale_commands = true;
  Rig rig(options);
  auto labelled = [](std::vector<double> w, std::int64_t stamp_ns) {
    msg::Float64MultiArray m = command(std::move(w));
    m.dim.push_back({msg::command_label(stamp_ns), 4, 4});
    return m;
  };
  rig.plant->publish_outputs(0);
  rig.cmd.publish(labelled({100, 200, 300, 400}, 0));
  rig.cmd.publish(labelled({100, 200, 300, 400}, 0));  // the same answer again
  rig.plant->latch_command(0);
  rig.plant->integrate(0);
  rig.tick(1);
  rig.plant->publish_outputs(2);
  rig.cmd.publish(labelled({1, 2, 3}, 20'000'000));  // a refused answer, and its copy
  rig.cmd.publish(labelled({1, 2, 3}, 20'000'000));
  rig.cmd.publish(labelled({5, 6, 7, 8}, 0));  // an answer to an earlier tick
  const PlantStats& st = rig.plant->stats();
  EXPECT_EQ(st.commands_received, 5u);
  EXPECT_EQ(st.commands_accepted, 1u);
  EXPECT_EQ(st.commands_rejected_length, 1u);
  EXPECT_EQ(st.commands_stale, 3u);
  EXPECT_EQ(rig.plant->applied_command(), model::Vector4(100, 200, 300, 400));
}

TEST(PlantValidationTest, LogIsRateLimitedAndSaysHowMany) {
  Rig rig;
  rig.tick(0);
  for (int i = 0; i < 250; ++i) rig.cmd.publish(command({}));
  ASSERT_EQ(rig.log.size(), 3u);
  EXPECT_NE(rig.log[0].find("0 values, expected 4 rotor speeds"), std::string::npos) << rig.log[0];
  EXPECT_NE(rig.log[0].find("1 rejected so far"), std::string::npos) << rig.log[0];
  EXPECT_NE(rig.log[2].find("201 rejected so far"), std::string::npos) << rig.log[2];
  EXPECT_EQ(rig.plant->stats().commands_rejected, 250u);
}

TEST(PlantValidationTest, HostileCommandStreamNeverMakesTheStateNonFinite) {
  Rig rig;
  const double big = std::numeric_limits<double>::max();
  const std::vector<std::vector<double>> evil = {{big, big, big, big},       {-big, big, -big, big},
                                                 {kNaN, kNaN, kNaN, kNaN},   {big, 0, big, 0},
                                                 {1e-320, 0, 1e-320, 0},     {0, big, 0, big},
                                                 {12000, 0, 12000, 0},       {}};
  for (Tick k = 0; k < 400; ++k) {
    rig.cmd.publish(command(evil[static_cast<std::size_t>(k) % evil.size()]));
    rig.tick(k);
    const model::State& x = rig.plant->state();
    ASSERT_TRUE(x.p_W.allFinite() && x.v_W.allFinite() && x.w_B.allFinite() && x.omega_rad_s.allFinite() &&
                x.q_WB.coeffs().allFinite())
        << "tick " << k;
  }
}

// The controller alone, fed by the test.
struct ControllerRig {
  InProcessTransport bus;
  Topics topics = Topics::for_namespace("/drone");
  Publisher<msg::PoseStamped> pose;
  Publisher<msg::TwistStamped> velocity;
  Publisher<msg::Imu> imu;
  std::vector<std::string> log;
  std::unique_ptr<ControllerNode> node;

  ControllerRig() {
    pose = bus.advertise<msg::PoseStamped>(topics.pose);
    velocity = bus.advertise<msg::TwistStamped>(topics.velocity);
    imu = bus.advertise<msg::Imu>(topics.imu);
    control::ControllerConfig cfg;
    cfg.params.safety = control::SafetyMode::kHover;  // a safety command that is not all zeros
    cfg.setpoint.p_des_W.z() = 5.0;
    node = std::make_unique<ControllerNode>(bus, topics, cfg);
    node->set_log([this](const std::string& line) { log.push_back(line); });
  }
  void send(std::int64_t ns, double q_w, double z) {
    msg::PoseStamped p = pose_at(ns);
    p.position.z = z;
    p.orientation.w = q_w;
    pose.publish(p);
    msg::TwistStamped t;
    t.header.stamp = msg::Time::from_ns(ns);
    velocity.publish(t);
    msg::Imu i;
    i.header.stamp = msg::Time::from_ns(ns);
    i.orientation.w = q_w;
    imu.publish(i);
  }
};

TEST(ControllerValidationTest, OnlyInvalidSensorDataGivesTheSafetyCommand) {
  ControllerRig rig;
  const double hover = std::sqrt(1.96 * 9.81 / (4 * 2.06e-7));  // Table 1: sqrt(m g / 4 kt)
  for (int k = 0; k < 50; ++k) {
    const std::int64_t ns = k * 20'000'000LL;
    rig.send(ns, 0.0, 1.0);  // zero quaternions: Pose and Imu refused
    msg::TwistStamped t;     // NaN velocity: refused
    t.header.stamp = msg::Time::from_ns(ns);
    t.linear.x = kNaN;
    rig.velocity.publish(t);
    const control::Command& c = rig.node->step(ns, 0.02);
    ASSERT_TRUE(c.safety) << "step " << k;
    for (int i = 0; i < 4; ++i) EXPECT_NEAR(c.omega_rad_s[i], hover, 1e-9);
  }
  const msg::ControllerStatus& s = rig.node->status();
  EXPECT_TRUE(s.safety);
  EXPECT_EQ(s.rejected_bad_quaternion, 100u);  // Pose and Imu, 50 each
  // Velocity: the valid-but-zero one of send() is accepted, the NaN one refused.
  EXPECT_EQ(s.rejected_non_finite, 50u);
  EXPECT_EQ(s.rejected_stamp_backwards, 0u);
  // Logged per reason: the 1st, then the 101st, ...: 100 quaternion and 50 non-finite refusals give
  // one line each.
  EXPECT_EQ(rig.log.size(), 2u);
}

TEST(ControllerValidationTest, ValidDataRecoversAndBackwardStampsAreRefused) {
  ControllerRig rig;
  rig.send(0, 1.0, 5.0);
  EXPECT_FALSE(rig.node->step(0, 0.02).safety);
  EXPECT_EQ(rig.node->estimate().p_W.z(), 5.0);
  // Newer data, then a stale replay with a different position: the replay is refused.
  rig.send(40'000'000, 1.0, 5.0);
  rig.send(20'000'000, 1.0, 99.0);
  EXPECT_EQ(rig.node->status().rejected_stamp_backwards, 0u) << "counted at arrival, published at step";
  EXPECT_FALSE(rig.node->step(40'000'000, 0.02).safety);
  EXPECT_EQ(rig.node->estimate().p_W.z(), 5.0);
  EXPECT_EQ(rig.node->status().rejected_stamp_backwards, 3u);
  // Only refused data from now on: the valid data of t = 0.04 s ages past the 0.1 s limit.
  for (std::int64_t ns = 60'000'000; ns <= 200'000'000; ns += 20'000'000) {
    rig.send(ns, kNaN, 5.0);
    const bool stale = ns - 40'000'000 > 100'000'000;
    EXPECT_EQ(rig.node->step(ns, 0.02).safety, stale) << "t = " << ns << " ns";
  }
}

TEST(ControllerValidationTest, ASenderWhoseClockRestartedIsFollowedAfterARunOfOldSamples) {
  ControllerRig rig;
  rig.send(50'000'000'000, 1.0, 5.0);  // t = 50 s
  EXPECT_FALSE(rig.node->step(50'000'000'000, 0.02).safety);
  // The sender starts again from t = 0: refused (and the data ages into the safety) until
  // kStampRestartCount samples in a row were refused on each topic; the next is accepted.
  for (int k = 0; k < kStampRestartCount; ++k) rig.send(k * 10'000'000LL, 1.0, 7.0);
  EXPECT_EQ(rig.node->estimate().p_W.z(), 5.0);
  EXPECT_TRUE(rig.node->step(50'500'000'000, 0.02).safety);
  EXPECT_EQ(rig.node->status().rejected_stamp_backwards, 3u * kStampRestartCount);
  rig.send(kStampRestartCount * 10'000'000LL, 1.0, 7.0);
  EXPECT_EQ(rig.node->estimate().p_W.z(), 7.0);
  // Time is measured by stamps here, so "now" follows the sender's new clock.
  EXPECT_FALSE(rig.node->step(kStampRestartCount * 10'000'000LL, 0.02).safety);
  // A single old sample after that is refused again.
  rig.send(0, 1.0, 9.0);
  EXPECT_EQ(rig.node->estimate().p_W.z(), 7.0);
}

TEST(ValidateSensorTest, ContentIsCheckedBeforeTheStamp) {
  msg::PoseStamped p = pose_at(0);
  p.position.x = kNaN;
  EXPECT_EQ(validate_pose(p, 10).fault, SensorFault::kNonFinite);  // old and NaN: reported as NaN
}

}  // namespace
}  // namespace quadcosim::sim
