// Tests of the checks on incoming messages (sim/validation.hpp) and of how the plant and the
// controller count, log and survive what they refuse.
#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <limits>
#include <string>
#include <vector>

#include "controllers/registry.hpp"
#include "sim/controller_node.hpp"
#include "sim/inprocess_transport.hpp"
#include "sim/plant_node.hpp"
#include "sim/plant_rig_test_support.hpp"
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

TEST(CheckCommandTest, FourFiniteSpeedsInRangeAreUsedAsSent) {
  const CommandCheck c = check_command(command({0.0, 1.5, 4830.6, 12000.0}), 12000.0);
  EXPECT_EQ(c.verdict(), CommandVerdict::kAccepted);
  EXPECT_EQ(c.fault, CommandFault::kNone);
  EXPECT_EQ(c.omega_rad_s, model::Vector4(0.0, 1.5, 4830.6, 12000.0));
  EXPECT_EQ(c.reason(), "");
  // A negative zero is in range and is used as sent, sign included.
  const CommandCheck z = check_command(command({-0.0, 1e-300, 1.0, 2.0}), 12000.0);
  EXPECT_EQ(z.fault, CommandFault::kNone);
  EXPECT_TRUE(std::signbit(z.omega_rad_s[0]));
  EXPECT_EQ(z.omega_rad_s[1], 1e-300);
}

// One speed at a time in rotor 3 of {100, 200, x, 300}, each outcome stated by hand.
TEST(CheckCommandTest, EachSpeedGetsItsVerdictTheSpeedToUseAndTheReason) {
  struct Case {
    double sent;
    CommandFault fault;
    double used;  // rotor 3's speed to use (not for a rejection)
    std::string reason;
  };
  const std::vector<Case> cases = {
      {0.0, CommandFault::kNone, 0.0, ""},
      {1e-300, CommandFault::kNone, 1e-300, ""},
      {4830.6, CommandFault::kNone, 4830.6, ""},
      {12000.0, CommandFault::kNone, 12000.0, ""},
      {-1e-300, CommandFault::kOutOfRange, 0.0, "rotor 3 speed -1e-300 rad/s clamped to 0 (range [0, 12000])"},
      {-5.0, CommandFault::kOutOfRange, 0.0, "rotor 3 speed -5 rad/s clamped to 0 (range [0, 12000])"},
      {std::nextafter(12000.0, 1e9), CommandFault::kOutOfRange, 12000.0,
       "rotor 3 speed 12000 rad/s clamped to 12000 (range [0, 12000])"},
      {1e9, CommandFault::kOutOfRange, 12000.0, "rotor 3 speed 1e+09 rad/s clamped to 12000 (range [0, 12000])"},
      {kInf, CommandFault::kNonFinite, 0.0, "rotor 3 speed is inf, expected a finite number"},
      {-kInf, CommandFault::kNonFinite, 0.0, "rotor 3 speed is -inf, expected a finite number"},
      {kNaN, CommandFault::kNonFinite, 0.0, "rotor 3 speed is nan, expected a finite number"},
  };
  for (const Case& k : cases) {
    const CommandCheck c = check_command(command({100.0, 200.0, k.sent, 300.0}), 12000.0);
    SCOPED_TRACE(k.reason.empty() ? std::to_string(k.sent) : k.reason);
    EXPECT_EQ(c.fault, k.fault);
    EXPECT_EQ(c.reason(), k.reason);
    const CommandVerdict verdict = k.fault == CommandFault::kNone         ? CommandVerdict::kAccepted
                                   : k.fault == CommandFault::kOutOfRange ? CommandVerdict::kClamped
                                                                          : CommandVerdict::kRejected;
    EXPECT_EQ(c.verdict(), verdict);
    if (k.fault != CommandFault::kNone) {
      EXPECT_EQ(c.rotor, 2);
      EXPECT_TRUE(c.value == k.sent || (std::isnan(c.value) && std::isnan(k.sent))) << c.value;
    }
    if (verdict != CommandVerdict::kRejected) {
      EXPECT_EQ(c.omega_rad_s, model::Vector4(100.0, 200.0, k.used, 300.0));
    }
  }
}

TEST(CheckCommandTest, WrongLengthAndNonFiniteAreRejectedWithTheReason) {
  struct Case {
    std::vector<double> data;
    CommandFault fault;
    std::string reason;
  };
  const std::vector<Case> cases = {
      {{}, CommandFault::kWrongLength, "0 values, expected 4 rotor speeds"},
      {{1, 2, 3}, CommandFault::kWrongLength, "3 values, expected 4 rotor speeds"},
      {{1, 2, 3, 4, 5}, CommandFault::kWrongLength, "5 values, expected 4 rotor speeds"},
      {{kNaN, kNaN, kNaN}, CommandFault::kWrongLength, "3 values, expected 4 rotor speeds"},  // length first
      {{1, kNaN, 3, 4}, CommandFault::kNonFinite, "rotor 2 speed is nan, expected a finite number"},
      {{1, 2, 3, kInf}, CommandFault::kNonFinite, "rotor 4 speed is inf, expected a finite number"},
      {{-kInf, 2, 3, 4}, CommandFault::kNonFinite, "rotor 1 speed is -inf, expected a finite number"},
      // A non-finite speed is reported before an out-of-range one on an earlier rotor, and the first
      // non-finite one is named.
      {{-5, 1e9, kInf, kNaN}, CommandFault::kNonFinite, "rotor 3 speed is inf, expected a finite number"},
  };
  for (const auto& c : cases) {
    const CommandCheck r = check_command(command(c.data), 12000.0);
    EXPECT_EQ(r.verdict(), CommandVerdict::kRejected) << c.reason;
    EXPECT_EQ(r.fault, c.fault) << c.reason;
    EXPECT_EQ(r.values, c.data.size()) << c.reason;
    EXPECT_EQ(r.omega_rad_s, model::Vector4::Zero()) << c.reason;
    EXPECT_EQ(r.reason(), c.reason);
  }
}

TEST(CheckCommandTest, NegativeAndTooFastAreClampedToTheMotorRangeAndTheFirstIsNamed) {
  const CommandCheck c = check_command(command({-5.0, 100.0, 1e9, -1e-300}), 12000.0);
  EXPECT_EQ(c.verdict(), CommandVerdict::kClamped);
  EXPECT_EQ(c.omega_rad_s, model::Vector4(0.0, 100.0, 12000.0, 0.0));
  EXPECT_EQ(c.rotor, 0);
  EXPECT_EQ(c.value, -5.0);
  EXPECT_EQ(c.reason(), "rotor 1 speed -5 rad/s clamped to 0 (range [0, 12000])");
  const CommandCheck d = check_command(command({1.0, 2.0, 1e9, -1.0}), 800.0);
  EXPECT_EQ(d.omega_rad_s, model::Vector4(1.0, 2.0, 800.0, 0.0));
  EXPECT_EQ(d.reason(), "rotor 3 speed 1e+09 rad/s clamped to 800 (range [0, 800])");
}

msg::PoseStamped pose_at(std::int64_t ns) {
  msg::PoseStamped m;
  m.header.stamp = msg::Time::from_ns(ns);
  m.position = {1.0, 2.0, 3.0};
  return m;
}

TEST(CheckSensorTest, PlantOutputsPass) {
  const SensorCheck p = check_pose(pose_at(0), kNever);
  EXPECT_TRUE(p.ok());
  EXPECT_EQ(p.field, SensorField::kNone);
  EXPECT_EQ(p.reason(), "");
  msg::TwistStamped t;
  EXPECT_TRUE(check_velocity(t, kNever).ok());
  msg::Imu imu;
  imu.orientation = {0.0, 0.0, std::sin(0.5), std::cos(0.5)};  // yaw 1 rad
  EXPECT_TRUE(check_imu(imu, kNever).ok());
}

// Every field checked, each fault, and the text of each reason.
TEST(CheckSensorTest, EachFaultNamesTheFieldAndValue) {
  struct Case {
    SensorCheck check;
    SensorFault fault;
    SensorField field;
    std::string reason;
  };
  std::vector<Case> cases;
  auto pose = [&](auto change, std::int64_t last, SensorFault f, SensorField field, std::string reason) {
    msg::PoseStamped m = pose_at(30'000'000);
    change(m);
    cases.push_back({check_pose(m, last), f, field, std::move(reason)});
  };
  auto velocity = [&](auto change, std::int64_t last, SensorFault f, SensorField field, std::string reason) {
    msg::TwistStamped m;
    m.header.stamp = msg::Time::from_ns(30'000'000);
    change(m);
    cases.push_back({check_velocity(m, last), f, field, std::move(reason)});
  };
  auto imu = [&](auto change, std::int64_t last, SensorFault f, SensorField field, std::string reason) {
    msg::Imu m;
    m.header.stamp = msg::Time::from_ns(30'000'000);
    change(m);
    cases.push_back({check_imu(m, last), f, field, std::move(reason)});
  };
  using F = SensorFault;
  using S = SensorField;
  pose([](auto& m) { m.position.y = kNaN; }, kNever, F::kNonFinite, S::kPosition,
       "position (1, nan, 3): expected finite values");
  pose([](auto& m) { m.orientation.x = kInf; }, kNever, F::kNonFinite, S::kOrientation,
       "orientation (x inf, y 0, z 0, w 1): expected finite values");
  pose(
      [](auto& m) {
        m.orientation = {0, 0, 0, 0};
      },
      kNever, F::kBadQuaternion, S::kOrientation,
      "orientation (x 0, y 0, z 0, w 0) has norm 0: expected a unit quaternion (within 0.001)");
  pose(
      [](auto& m) {
        m.header.stamp = {1, 1'000'000'000u};
      },
      kNever, F::kBadStamp, S::kStamp, "stamp sec 1 nanosec 1000000000: expected sec >= 0 and nanosec < 1e9");
  pose(
      [](auto& m) {
        m.header.stamp = {-1, 0};
      },
      kNever, F::kBadStamp, S::kStamp, "stamp sec -1 nanosec 0: expected sec >= 0 and nanosec < 1e9");
  pose([](auto&) {}, 40'000'000, F::kStampBackwards, S::kStamp,
       "stamp 30000000 ns is older than the newest accepted, 40000000 ns");
  velocity([](auto& m) { m.linear.x = -kInf; }, kNever, F::kNonFinite, S::kLinear,
           "linear (-inf, 0, 0): expected finite values");
  velocity([](auto& m) { m.angular.z = kNaN; }, kNever, F::kNonFinite, S::kAngular,
           "angular (0, 0, nan): expected finite values");
  velocity([](auto& m) { m.header.stamp.nanosec = 2'000'000'000u; }, kNever, F::kBadStamp, S::kStamp,
           "stamp sec 0 nanosec 2000000000: expected sec >= 0 and nanosec < 1e9");
  velocity([](auto&) {}, 30'000'001, F::kStampBackwards, S::kStamp,
           "stamp 30000000 ns is older than the newest accepted, 30000001 ns");
  imu([](auto& m) { m.orientation.w = kNaN; }, kNever, F::kNonFinite, S::kOrientation,
      "orientation (x 0, y 0, z 0, w nan): expected finite values");
  imu(
      [](auto& m) {
        m.orientation = {0.6, 0, 0, 0.6};
      },
      kNever, F::kBadQuaternion, S::kOrientation,
      "orientation (x 0.6, y 0, z 0, w 0.6) has norm 0.848528: expected a unit quaternion (within 0.001)");
  // Finite, but |q|^2 overflows: not a unit quaternion (not a non-finite value).
  imu(
      [](auto& m) {
        m.orientation = {1e200, 0, 0, 1};
      },
      kNever, F::kBadQuaternion, S::kOrientation,
      "orientation (x 1e+200, y 0, z 0, w 1) has norm inf: expected a unit quaternion (within 0.001)");
  imu([](auto& m) { m.angular_velocity.y = kInf; }, kNever, F::kNonFinite, S::kAngularVelocity,
      "angular_velocity (0, inf, 0): expected finite values");
  imu([](auto& m) { m.linear_acceleration.z = kNaN; }, kNever, F::kNonFinite, S::kLinearAcceleration,
      "linear_acceleration (0, 0, nan): expected finite values");
  imu(
      [](auto& m) {
        m.header.stamp = {-5, 7};
      },
      kNever, F::kBadStamp, S::kStamp, "stamp sec -5 nanosec 7: expected sec >= 0 and nanosec < 1e9");
  imu([](auto&) {}, 1'000'000'000, F::kStampBackwards, S::kStamp,
      "stamp 30000000 ns is older than the newest accepted, 1000000000 ns");
  ASSERT_EQ(cases.size(), 17u);
  for (const Case& c : cases) {
    EXPECT_FALSE(c.check.ok()) << c.reason;
    EXPECT_EQ(c.check.fault, c.fault) << c.reason;
    EXPECT_EQ(c.check.field, c.field) << c.reason;
    EXPECT_EQ(c.check.reason(), c.reason);
  }
}

TEST(CheckSensorTest, TheCheckCarriesTheValuesAndStampsAsPlainData) {
  msg::PoseStamped p = pose_at(0);
  p.position.z = -kInf;
  SensorCheck c = check_pose(p, kNever);
  EXPECT_EQ(c.value, (std::array<double, 4>{1.0, 2.0, -kInf, 0.0}));
  p = pose_at(0);
  p.orientation = {0.1, 0.2, 0.3, 0.4};
  c = check_pose(p, kNever);
  EXPECT_EQ(c.value, (std::array<double, 4>{0.1, 0.2, 0.3, 0.4}));
  c = check_pose(pose_at(1'500'000'000), 2'000'000'000);
  EXPECT_EQ(c.stamp.sec, 1);
  EXPECT_EQ(c.stamp.nanosec, 500'000'000u);
  EXPECT_EQ(c.newest_ns, 2'000'000'000);
}

TEST(CheckSensorTest, TheFirstFaultInTheStatedOrderIsReported) {
  // Pose: position, orientation, stamp.
  msg::PoseStamped p = pose_at(0);
  p.position.x = kNaN;
  p.orientation = {0, 0, 0, 0};
  p.header.stamp = {-1, 0};
  EXPECT_EQ(check_pose(p, kNever).field, SensorField::kPosition);
  p.position.x = 1.0;
  EXPECT_EQ(check_pose(p, kNever).fault, SensorFault::kBadQuaternion);
  // An orientation: NaN/Inf before the norm.
  p.orientation.x = kNaN;
  EXPECT_EQ(check_pose(p, kNever).fault, SensorFault::kNonFinite);
  // The content before the stamp: old and NaN is reported as NaN.
  p = pose_at(0);
  p.position.x = kNaN;
  EXPECT_EQ(check_pose(p, 10).fault, SensorFault::kNonFinite);
  // A stamp: malformed before backwards (sec -1 is also older than 0).
  p = pose_at(0);
  p.header.stamp = {-1, 0};
  EXPECT_EQ(check_pose(p, 0).fault, SensorFault::kBadStamp);
  // Velocity: linear, angular, stamp.
  msg::TwistStamped t;
  t.linear.y = kNaN;
  t.angular.y = kNaN;
  EXPECT_EQ(check_velocity(t, 10).field, SensorField::kLinear);
  t.linear.y = 0.0;
  EXPECT_EQ(check_velocity(t, 10).field, SensorField::kAngular);
  t.angular.y = 0.0;
  EXPECT_EQ(check_velocity(t, 10).field, SensorField::kStamp);
  // Imu: orientation, angular_velocity, linear_acceleration, stamp.
  msg::Imu i;
  i.orientation = {0, 0, 0, 0};
  i.angular_velocity.x = kInf;
  i.linear_acceleration.x = kInf;
  EXPECT_EQ(check_imu(i, 10).field, SensorField::kOrientation);
  i.orientation.w = 1.0;
  EXPECT_EQ(check_imu(i, 10).field, SensorField::kAngularVelocity);
  i.angular_velocity.x = 0.0;
  EXPECT_EQ(check_imu(i, 10).field, SensorField::kLinearAcceleration);
  i.linear_acceleration.x = 0.0;
  EXPECT_EQ(check_imu(i, 10).field, SensorField::kStamp);
  EXPECT_TRUE(check_imu(i, 0).ok());
}

TEST(CheckSensorTest, QuaternionsMustBeUnitWithinTheStatedTolerance) {
  msg::Imu imu;
  const double tol = kQuaternionNormTolerance;
  auto with_w = [&](double x, double w) {
    imu.orientation = {x, 0.0, 0.0, w};
    return check_imu(imu, kNever).fault;
  };
  EXPECT_EQ(with_w(0.0, 0.0), SensorFault::kBadQuaternion);  // zero
  EXPECT_EQ(with_w(0.0, 1.0 + 2 * tol), SensorFault::kBadQuaternion);
  EXPECT_EQ(with_w(0.0, 1.0 - 2 * tol), SensorFault::kBadQuaternion);
  EXPECT_EQ(with_w(0.0, 1.0 + 0.5 * tol), SensorFault::kNone);
  EXPECT_EQ(with_w(0.0, 1.0 - 0.5 * tol), SensorFault::kNone);
  EXPECT_EQ(with_w(0.0, -1.0), SensorFault::kNone);          // -q is the same rotation
  EXPECT_EQ(with_w(0.6, 0.8), SensorFault::kNone);           // 0.36 + 0.64 = 1
  EXPECT_EQ(with_w(0.6, 0.6), SensorFault::kBadQuaternion);  // norm 0.849
  msg::PoseStamped p = pose_at(0);
  p.orientation = {0, 0, 0, 0};
  EXPECT_EQ(check_pose(p, kNever).fault, SensorFault::kBadQuaternion);
}

TEST(CheckSensorTest, StampsMayRepeatButNotGoBackOrBeMalformed) {
  EXPECT_EQ(check_pose(pose_at(20'000'000), 20'000'000).fault, SensorFault::kNone);
  EXPECT_EQ(check_pose(pose_at(10'000'000), 20'000'000).fault, SensorFault::kStampBackwards);
  EXPECT_EQ(check_pose(pose_at(0), kNever).fault, SensorFault::kNone);
  msg::PoseStamped p = pose_at(0);
  p.header.stamp = {1, 999'999'999u};
  EXPECT_EQ(check_pose(p, kNever).fault, SensorFault::kNone);
  p.header.stamp = {1, 1'000'000'000u};
  EXPECT_EQ(check_pose(p, kNever).fault, SensorFault::kBadStamp);
  p.header.stamp = {-1, 0};
  EXPECT_EQ(check_pose(p, kNever).fault, SensorFault::kBadStamp);
}

TEST(CheckSensorTest, NamesOfFaultsAndFields) {
  EXPECT_STREQ(to_string(SensorFault::kNone), "accepted");
  EXPECT_STREQ(to_string(SensorFault::kNonFinite), "non-finite value");
  EXPECT_STREQ(to_string(SensorFault::kBadQuaternion), "non-unit quaternion");
  EXPECT_STREQ(to_string(SensorFault::kBadStamp), "malformed stamp");
  EXPECT_STREQ(to_string(SensorFault::kStampBackwards), "stamp went backwards");
  EXPECT_STREQ(to_string(SensorField::kLinearAcceleration), "linear_acceleration");
  EXPECT_STREQ(to_string(SensorField::kStamp), "stamp");
}

TEST(LogThrottleTest, LogsTheFirstThenEveryNth) {
  LogThrottle t(100);
  std::vector<std::uint64_t> logged;
  for (int i = 0; i < 250; ++i) {
    if (t.count()) logged.push_back(t.total());
  }
  EXPECT_EQ(logged, (std::vector<std::uint64_t>{1, 101, 201}));
}

// A plant on its own bus, 10 m up and at rest, without a watchdog; the test plays the controller and
// watches the plant status.
struct Rig : test::PlantRig {
  explicit Rig(PlantOptions options = {}) : PlantRig(without_watchdog(options), at_rest_10_m()) {}
  static model::State at_rest_10_m() {
    model::State x0;
    x0.p_W.z() = 10.0;
    return x0;
  }
  void tick(Tick k) {
    plant.publish_outputs(k);
    latch_and_integrate(k);
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
  EXPECT_EQ(rig.log, (std::vector<std::string>{
                         "plant: motor command rejected (3 values, expected 4 rotor speeds), last good command "
                         "held; 1 rejected so far (logged: 1st, then every 100th)",
                         "plant: motor command clamped (rotor 1 speed -1 rad/s clamped to 0 (range [0, 12000])); 1 "
                         "clamped so far (logged: 1st, then every 100th)"}));
  EXPECT_EQ(rig.plant.latched_command(), model::Vector4(0, 2, 3, 4));
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
  rig.plant.publish_outputs(0);
  rig.cmd.publish(labelled({100, 200, 300, 400}, 0));
  rig.cmd.publish(labelled({100, 200, 300, 400}, 0));  // the same answer again
  rig.plant.latch_command(0);
  rig.plant.integrate(0);
  rig.tick(1);
  rig.plant.publish_outputs(2);
  // A refused answer, and its copy: the label of a refused command is not remembered (what a command
  // says of its tick counts only once it is known to be a command), so the copy is refused again, not
  // dropped as a repeat.
  rig.cmd.publish(labelled({1, 2, 3}, 20'000'000));
  rig.cmd.publish(labelled({1, 2, 3}, 20'000'000));
  rig.cmd.publish(labelled({5, 6, 7, 8}, 0));  // an answer to an earlier tick
  const PlantStats& st = rig.plant.stats();
  EXPECT_EQ(st.commands_received, 5u);
  EXPECT_EQ(st.commands_accepted, 1u);
  EXPECT_EQ(st.commands_rejected_length, 2u);
  EXPECT_EQ(st.commands_stale, 2u);
  EXPECT_EQ(rig.plant.latched_command(), model::Vector4(100, 200, 300, 400));
  // The refused answer answered tick 2 (the last good command held, as in-process).
  EXPECT_EQ(rig.plant.command_receipt().label_ns, 20'000'000);
}

// A command labelled with a stamp behind the current tick is told to the host with that label and
// the tick (a ROS-time timer that stepped on older samples); a copy of the tick's accepted answer is
// no such command.
TEST(PlantValidationTest, ALabelBehindTheTickIsToldWithTheTick) {
  PlantOptions options;
  options.drop_stale_commands = true;
  Rig rig(options);
  std::vector<std::pair<std::int64_t, Tick>> told;
  rig.plant.on_label_behind([&](std::int64_t label_ns, Tick k) { told.emplace_back(label_ns, k); });
  auto labelled = [](std::vector<double> w, std::int64_t stamp_ns) {
    msg::Float64MultiArray m = command(std::move(w));
    m.dim.push_back({msg::command_label(stamp_ns), 4, 4});
    return m;
  };
  for (Tick k = 0; k < 4; ++k) rig.tick(k);
  rig.plant.publish_outputs(4);                                 // t = 0.04 s
  rig.cmd.publish(labelled({100, 200, 300, 400}, 40'000'000));  // the tick's answer
  rig.cmd.publish(labelled({100, 200, 300, 400}, 40'000'000));  // its copy: a repeat, not behind
  EXPECT_TRUE(told.empty());
  rig.cmd.publish(labelled({1, 2, 3, 4}, 30'000'000));  // on the samples of tick 3
  ASSERT_EQ(told.size(), 1u);
  EXPECT_EQ(told[0], (std::pair<std::int64_t, Tick>{30'000'000, 4}));
  EXPECT_EQ(rig.plant.stats().commands_stale, 2u);
  rig.plant.latch_command(4);
  EXPECT_EQ(rig.plant.latched_command(), model::Vector4(100, 200, 300, 400));
}

// A NaN command labelled with the current tick, then the valid answer with the same label: the valid
// one is taken, not dropped as a copy of the NaN.
TEST(PlantValidationTest, ANonFiniteCommandLabelledWithTheTickDoesNotMakeTheAnswerARepeat) {
  PlantOptions options;
  options.drop_stale_commands = true;
  Rig rig(options);
  auto labelled = [](std::vector<double> w, std::int64_t stamp_ns) {
    msg::Float64MultiArray m = command(std::move(w));
    m.dim.push_back({msg::command_label(stamp_ns), 4, 4});
    return m;
  };
  rig.plant.publish_outputs(0);
  rig.cmd.publish(labelled({kNaN, 1, 1, 1}, 0));
  rig.cmd.publish(labelled({100, 200, 300, 400}, 0));
  rig.plant.latch_command(0);
  const PlantStats& st = rig.plant.stats();
  EXPECT_EQ(st.commands_rejected_non_finite, 1u);
  EXPECT_EQ(st.commands_accepted, 1u);
  EXPECT_EQ(st.commands_stale, 0u);
  EXPECT_EQ(rig.plant.latched_command(), model::Vector4(100, 200, 300, 400));
}

// Commands whose sender the filter refuses are foreign: counted, logged once per 100, and nothing
// else: not received, not an answer, no label seen, nothing latched.
TEST(PlantValidationTest, CommandsOfAnotherWriterAreForeignAndChangeNothing) {
  PlantOptions options;
  options.drop_stale_commands = true;
  Rig rig(options);
  // The in-process transport says 0 for every sender: a filter refusing it makes every command foreign.
  rig.plant.set_command_filter([](const std::string&, SenderId s) { return s != 0; });
  const model::Vector4 before = rig.plant.latched_command();
  msg::Float64MultiArray m = command({100, 200, 300, 400});
  m.dim.push_back({msg::command_label(0), 4, 4});
  rig.plant.publish_outputs(0);
  for (int i = 0; i < 150; ++i) rig.cmd.publish(m);
  rig.plant.latch_command(0);
  const PlantStats& st = rig.plant.stats();
  EXPECT_EQ(st.commands_foreign, 150u);
  EXPECT_EQ(st.commands_received, 0u);
  EXPECT_EQ(st.commands_accepted, 0u);
  EXPECT_EQ(st.commands_stale, 0u);
  EXPECT_EQ(rig.plant.command_receipt().received, 0u);
  EXPECT_EQ(rig.plant.command_receipt().label_ns, -1);
  EXPECT_EQ(rig.plant.latched_command(), before);
  ASSERT_EQ(rig.log.size(), 2u);  // the 1st and the 101st
  EXPECT_EQ(rig.log[0],
            "plant: motor command from a writer other than the controller's ignored; 1 ignored so far (logged: 1st, "
            "then every 100th)");
  // The count is published in the plant status.
  rig.tick(1);
  ASSERT_FALSE(rig.statuses.empty());
  EXPECT_EQ(rig.statuses.back().commands_foreign, 150u);
}

TEST(PlantValidationTest, LogIsRateLimitedAndSaysHowMany) {
  Rig rig;
  rig.tick(0);
  for (int i = 0; i < 250; ++i) rig.cmd.publish(command({}));
  ASSERT_EQ(rig.log.size(), 3u);
  EXPECT_NE(rig.log[0].find("0 values, expected 4 rotor speeds"), std::string::npos) << rig.log[0];
  EXPECT_NE(rig.log[0].find("1 rejected so far"), std::string::npos) << rig.log[0];
  EXPECT_NE(rig.log[2].find("201 rejected so far"), std::string::npos) << rig.log[2];
  EXPECT_EQ(rig.plant.stats().commands_rejected, 250u);
}

TEST(PlantValidationTest, HostileCommandStreamNeverMakesTheStateNonFinite) {
  Rig rig;
  const double big = std::numeric_limits<double>::max();
  const std::vector<std::vector<double>> evil = {
      {big, big, big, big},   {-big, big, -big, big}, {kNaN, kNaN, kNaN, kNaN}, {big, 0, big, 0},
      {1e-320, 0, 1e-320, 0}, {0, big, 0, big},       {12000, 0, 12000, 0},     {}};
  for (Tick k = 0; k < 400; ++k) {
    rig.cmd.publish(command(evil[static_cast<std::size_t>(k) % evil.size()]));
    rig.tick(k);
    const model::State& x = rig.plant.state();
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
    control::ControllerConfig cfg = controllers::make_config("paper", model::VehicleParams{});
    cfg.node.safety = control::SafetyMode::kHover;  // a safety command that is not all zeros
    cfg.node.setpoint.p_des_W.z() = 5.0;
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
    const control::ControllerOutput& c = rig.node->step(ns, 0.02);
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
  EXPECT_EQ(rig.log, (std::vector<std::string>{
                         "controller: /drone/Pose message rejected, non-unit quaternion (orientation (x 0, y 0, z 0, "
                         "w 0) has norm 0: expected a unit quaternion (within 0.001)); 1 rejected for this reason so "
                         "far (logged: 1st, then every 100th)",
                         "controller: /drone/Velocity message rejected, non-finite value (linear (nan, 0, 0): "
                         "expected finite values); 1 rejected for this reason so far (logged: 1st, then every "
                         "100th)"}));
}

TEST(ControllerValidationTest, ValidDataRecoversAndBackwardStampsAreRefused) {
  ControllerRig rig;
  rig.send(0, 1.0, 5.0);
  EXPECT_FALSE(rig.node->step(0, 0.02).safety);
  EXPECT_EQ(rig.node->observation().p_W.z(), 5.0);
  // Newer data, then a stale replay with a different position: the replay is refused.
  rig.send(40'000'000, 1.0, 5.0);
  rig.send(20'000'000, 1.0, 99.0);
  EXPECT_EQ(rig.node->status().rejected_stamp_backwards, 0u) << "counted at arrival, published at step";
  EXPECT_FALSE(rig.node->step(40'000'000, 0.02).safety);
  EXPECT_EQ(rig.node->observation().p_W.z(), 5.0);
  EXPECT_EQ(rig.node->status().rejected_stamp_backwards, 3u);
  // Only refused data from now on: the valid data of t = 0.04 s ages past the 0.1 s limit.
  for (std::int64_t ns = 60'000'000; ns <= 200'000'000; ns += 20'000'000) {
    rig.send(ns, kNaN, 5.0);
    const bool stale = ns - 40'000'000 > 100'000'000;
    EXPECT_EQ(rig.node->step(ns, 0.02).safety, stale) << "t = " << ns << " ns";
  }
}

// One sample stamped far in the future (a stranger's, a broken clock) does not become the newest: it is
// refused as too far ahead, and the genuine samples after it are taken, so the controller is not blinded.
TEST(ControllerValidationTest, ASampleStampedFarAheadIsRefusedAndDoesNotBlindTheController) {
  ControllerRig rig;
  rig.send(20'000'000, 1.0, 5.0);
  EXPECT_FALSE(rig.node->step(20'000'000, 0.02).safety);
  rig.send(2'000'000'000LL * 1'000'000'000LL, 1.0, 99.0);    // 2e9 s: refused on every topic
  rig.send(20'000'000 + kStampAheadLimitNs + 1, 1.0, 98.0);  // just beyond the limit: refused too
  for (std::int64_t ns = 40'000'000; ns <= 400'000'000; ns += 20'000'000) {
    rig.send(ns, 1.0, 5.0);
    EXPECT_FALSE(rig.node->step(ns, 0.02).safety) << "t = " << ns << " ns";
    EXPECT_EQ(rig.node->observation().p_W.z(), 5.0);
  }
  EXPECT_EQ(rig.node->status().rejected_stamp_ahead, 6u);  // two samples on each of the three topics
  EXPECT_EQ(rig.node->status().rejected_stamp_backwards, 0u);
  EXPECT_EQ(rig.node->status().header.stamp.to_ns(), 400'000'000) << "the future stamp leaked into the status";
  // A sample exactly at the limit is a sender's legitimate jump (a slow sensor): taken.
  rig.send(400'000'000 + kStampAheadLimitNs, 1.0, 6.0);
  EXPECT_EQ(rig.node->observation().p_W.z(), 6.0);
  EXPECT_NE(rig.log.front().find("stamp too far ahead (stamp 2000000000000000000 ns is 2e+09 s ahead of the newest "
                                 "accepted, 20000000 ns (at most 2 s))"),
            std::string::npos)
      << rig.log.front();
}

// Real time: a link cut for longer than the limit (3 s here) brings samples that far ahead when it heals.
// On the receipt clock the 3 s spent waiting are allowed on top of the limit, so the first sample
// across the healed link is taken at once (it was refused for kStampRestartCount samples, half a
// second of the safety command, when the limit did not grow); a stamp beyond that growth still is not.
TEST(ControllerValidationTest, OnTheReceiptClockTheTimeWaitedIsAllowedOnTopOfTheAheadLimit) {
  ControllerRig rig;
  std::int64_t wall_ns = 1'000'000'000'000;  // the node's steady clock, unrelated to the stamps
  rig.node->use_receipt_clock([&] { return wall_ns; });
  rig.send(1'000'000'000, 1.0, 5.0);  // t = 1 s
  EXPECT_FALSE(rig.node->step(wall_ns, 0.02).safety);
  wall_ns += 3'000'000'000;  // 3 s of cut link: nothing arrives
  EXPECT_TRUE(rig.node->step(wall_ns, 0.02).safety);
  rig.send(4'010'000'000, 1.0, 6.0);  // 3.01 s ahead: within 2 s + 3 s waited
  EXPECT_EQ(rig.node->observation().p_W.z(), 6.0);
  EXPECT_FALSE(rig.node->step(wall_ns, 0.02).safety);
  EXPECT_EQ(rig.node->status().rejected_stamp_ahead, 0u);
  // 2 s + the 10 ms since is what is allowed now: a stamp 2.5 s ahead of the newest is refused.
  wall_ns += 10'000'000;
  rig.send(4'010'000'000 + 2'500'000'000, 1.0, 7.0);
  EXPECT_EQ(rig.node->observation().p_W.z(), 6.0);
  rig.node->step(wall_ns, 0.02);  // the status counts as of the step
  EXPECT_EQ(rig.node->status().rejected_stamp_ahead, 3u);
  EXPECT_NE(rig.log.back().find("(at most 2.01 s)"), std::string::npos) << rig.log.back();
}

TEST(ControllerValidationTest, ASenderWhoseClockRestartedIsFollowedAfterARunOfOldSamples) {
  ControllerRig rig;
  rig.send(50'000'000'000, 1.0, 5.0);  // t = 50 s
  EXPECT_FALSE(rig.node->step(50'000'000'000, 0.02).safety);
  // The sender starts again from t = 0: refused (and the data ages into the safety) until
  // kStampRestartCount samples in a row were refused on each topic; the next is accepted.
  for (int k = 0; k < kStampRestartCount; ++k) rig.send(k * 10'000'000LL, 1.0, 7.0);
  EXPECT_EQ(rig.node->observation().p_W.z(), 5.0);
  EXPECT_TRUE(rig.node->step(50'500'000'000, 0.02).safety);
  EXPECT_EQ(rig.node->status().rejected_stamp_backwards, 3u * kStampRestartCount);
  rig.send(kStampRestartCount * 10'000'000LL, 1.0, 7.0);
  EXPECT_EQ(rig.node->observation().p_W.z(), 7.0);
  EXPECT_EQ(rig.log.back(),
            "controller: /drone/Imu: 50 samples in a row older than the newest accepted; taking it that the "
            "sender's clock restarted (stamp 500000000 ns is older than the newest accepted, 50000000000 ns)");
  // Time is measured by stamps here, so "now" follows the sender's new clock.
  EXPECT_FALSE(rig.node->step(kStampRestartCount * 10'000'000LL, 0.02).safety);
  // A single old sample after that is refused again.
  rig.send(0, 1.0, 9.0);
  EXPECT_EQ(rig.node->observation().p_W.z(), 7.0);
}

}  // namespace
}  // namespace quadcosim::sim
