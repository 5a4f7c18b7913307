// Faults in the co-simulation: the plant's watchdog (ticks and receipt clock) and the in-process
// transport's seeded message loss and delay, down to hover held under 10 % loss and a tick of delay.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <cstring>
#include <vector>

#include "controllers/registry.hpp"
#include "model/quadrotor.hpp"
#include "sim/inprocess_transport.hpp"
#include "sim/plant_node.hpp"
#include "sim/simulation.hpp"

namespace quadcosim::sim {
namespace {

struct WatchdogRig {
  InProcessTransport bus;
  Topics topics = Topics::for_namespace("/drone");
  model::VehicleParams vehicle;
  Publisher<msg::Float64MultiArray> cmd;
  std::unique_ptr<PlantNode> plant;

  explicit WatchdogRig(PlantOptions opt) {
    vehicle.motor.omega_min_rad_s = 150.0;  // so "stop" is told apart from zero
    cmd = bus.advertise<msg::Float64MultiArray>(topics.motor_commands);
    plant = std::make_unique<PlantNode>(bus, topics, vehicle, opt, model::State{});
  }
  /// A watchdog of `ticks` ticks with `policy`, the other options their defaults.
  explicit WatchdogRig(Tick ticks, WatchdogPolicy policy = PlantOptions{}.watchdog_policy)
      : WatchdogRig(watchdog(ticks, policy)) {}
  static PlantOptions watchdog(Tick ticks, WatchdogPolicy policy) {
    PlantOptions opt;
    opt.watchdog_ticks = ticks;
    opt.watchdog_policy = policy;
    return opt;
  }
  void send(double w) {
    msg::Float64MultiArray m;
    m.data = {w, w, w, w};
    cmd.publish(m);
  }
  /// Tick k with an optional command received during it.
  void tick(Tick k, double command = -1.0) {
    plant->publish_outputs(k);
    if (command >= 0.0) send(command);
    plant->latch_command(k);
  }
};

TEST(PlantWatchdogTest, StopPolicyActsAtTheLimitInTicksAndReleasesOnTheNextCommand) {
  WatchdogRig rig(5, WatchdogPolicy::kStop);
  rig.tick(0, 4000.0);
  for (Tick k = 1; k < 5; ++k) {  // 4 ticks without a command: within the limit
    rig.tick(k);
    EXPECT_FALSE(rig.plant->watchdog_active()) << k;
    EXPECT_EQ(rig.plant->latched_command(), model::Vector4::Constant(4000.0)) << k;
  }
  rig.tick(5);  // 5 ticks = 50 ms after the last command: the limit
  EXPECT_TRUE(rig.plant->watchdog_active());
  EXPECT_EQ(rig.plant->command_age_ns(), 50'000'000);
  EXPECT_EQ(rig.plant->latched_command(), model::Vector4::Constant(150.0));
  rig.tick(6);
  EXPECT_EQ(rig.plant->stats().watchdog_trips, 1u);
  EXPECT_EQ(rig.plant->stats().watchdog_ticks, 2u);
  rig.tick(7, 3000.0);  // a valid command: released at once
  EXPECT_FALSE(rig.plant->watchdog_active());
  EXPECT_EQ(rig.plant->latched_command(), model::Vector4::Constant(3000.0));
  for (Tick k = 8; k <= 12; ++k) rig.tick(k);
  EXPECT_TRUE(rig.plant->watchdog_active());
  EXPECT_EQ(rig.plant->stats().watchdog_trips, 2u);
}

TEST(PlantWatchdogTest, InvalidCommandsDoNotFeedTheWatchdog) {
  WatchdogRig rig(3);
  rig.tick(0, 4000.0);
  for (Tick k = 1; k <= 3; ++k) {
    rig.plant->publish_outputs(k);
    msg::Float64MultiArray bad;
    bad.data = {1.0, std::nan(""), 1.0, 1.0};
    rig.cmd.publish(bad);
    rig.plant->latch_command(k);
  }
  EXPECT_TRUE(rig.plant->watchdog_active());
  EXPECT_EQ(rig.plant->stats().commands_rejected, 3u);
}

TEST(PlantWatchdogTest, HoldPolicyKeepsTheLastCommandButCountsTheEvent) {
  WatchdogRig rig(2, WatchdogPolicy::kHold);
  rig.tick(0, 4321.0);
  for (Tick k = 1; k <= 4; ++k) rig.tick(k);
  EXPECT_TRUE(rig.plant->watchdog_active());
  EXPECT_EQ(rig.plant->latched_command(), model::Vector4::Constant(4321.0));
  EXPECT_EQ(rig.plant->stats().watchdog_trips, 1u);
  EXPECT_EQ(rig.plant->stats().watchdog_ticks, 3u);  // ticks 2, 3, 4
}

TEST(PlantWatchdogTest, ZeroSwitchesItOff) {
  WatchdogRig rig(0);
  rig.tick(0, 4000.0);
  for (Tick k = 1; k < 1000; ++k) rig.tick(k);
  EXPECT_FALSE(rig.plant->watchdog_active());
  EXPECT_EQ(rig.plant->latched_command(), model::Vector4::Constant(4000.0));
}

TEST(PlantWatchdogTest, ReceiptClockMeasuresWallTimeNotTicks) {
  WatchdogRig rig(5);  // 50 ms
  std::int64_t now_ns = 1'000'000'000;
  rig.plant->use_receipt_clock([&] { return now_ns; });
  rig.tick(0, 4000.0);
  // The same tick latched again while the wall clock runs (a stalled simulated clock): the limit
  // is reached by time alone.
  now_ns += 49'000'000;
  rig.plant->latch_command(0);
  EXPECT_FALSE(rig.plant->watchdog_active());
  now_ns += 1'000'000;
  rig.plant->latch_command(0);
  EXPECT_TRUE(rig.plant->watchdog_active());
  EXPECT_EQ(rig.plant->command_age_ns(), 50'000'000);
  // Many ticks in little wall time (a fast rate factor): no trip.
  now_ns += 1'000'000;
  rig.tick(1, 4000.0);
  for (Tick k = 2; k < 100; ++k) rig.tick(k);
  EXPECT_FALSE(rig.plant->watchdog_active());
}

TEST(PlantWatchdogTest, ReceiptClockStartsAtTheFirstTickWhenNothingArrives) {
  WatchdogRig rig(5);
  std::int64_t now_ns = 7'000'000'000;
  rig.plant->use_receipt_clock([&] { return now_ns; });
  rig.tick(0);
  EXPECT_FALSE(rig.plant->watchdog_active());
  now_ns += 50'000'000;
  rig.tick(1);
  EXPECT_TRUE(rig.plant->watchdog_active());
}

TEST(PlantWatchdogTest, ALockstepRepeatOfTheCurrentTickIsNotANewCommand) {
  PlantOptions opt;
  opt.drop_stale_commands = true;
  WatchdogRig rig(opt);
  msg::Float64MultiArray m;
  m.data = {4000, 4000, 4000, 4000};
  m.dim = {{msg::command_label(40'000'000), 4, 4}};
  rig.plant->publish_outputs(4);
  rig.cmd.publish(m);
  rig.plant->publish_outputs(4);  // the plant asks again; the controller answers again
  rig.cmd.publish(m);
  rig.plant->latch_command(4);
  EXPECT_EQ(rig.plant->stats().commands_accepted, 1u);
  EXPECT_EQ(rig.plant->stats().commands_stale, 1u);
  EXPECT_EQ(rig.plant->latched_command(), model::Vector4::Constant(4000.0));
}

// --- injected faults ----------------------------------------------------------------------------

TEST(FaultInjectionTest, DropsAtTheConfiguredRateOnlyOnItsTopic) {
  InProcessTransport bus;
  FaultConfig f;
  f.seed = 42;
  f.topics["/lossy"].drop_probability = 0.1;
  bus.set_faults(f);
  int lossy = 0, clean = 0;
  bus.subscribe<msg::Clock>("/lossy", [&](const msg::Clock&) { ++lossy; });
  bus.subscribe<msg::Clock>("/clean", [&](const msg::Clock&) { ++clean; });
  auto a = bus.advertise<msg::Clock>("/lossy");
  auto b = bus.advertise<msg::Clock>("/clean");
  constexpr int n = 20000;
  for (int i = 0; i < n; ++i) {
    a.publish(msg::Clock{});
    b.publish(msg::Clock{});
  }
  EXPECT_EQ(clean, n);
  EXPECT_EQ(static_cast<std::uint64_t>(lossy) + bus.dropped("/lossy"), static_cast<std::uint64_t>(n));
  // Binomial(n, 0.1): mean 2000, standard deviation sqrt(n p (1 - p)) = 42.4; allow 5 sigma.
  EXPECT_NEAR(static_cast<double>(bus.dropped("/lossy")), 2000.0, 5 * 42.4);
  EXPECT_EQ(bus.dropped("/clean"), 0u);
}

std::vector<int> survivors(std::uint64_t seed) {
  InProcessTransport bus;
  FaultConfig f;
  f.seed = seed;
  f.topics["/t"].drop_probability = 0.5;
  bus.set_faults(f);
  std::vector<int> got;
  bus.subscribe<msg::Clock>("/t", [&](const msg::Clock& m) { got.push_back(m.clock.sec); });
  auto p = bus.advertise<msg::Clock>("/t");
  for (int i = 0; i < 200; ++i) p.publish(msg::Clock{{i, 0}});
  return got;
}

TEST(FaultInjectionTest, SameSeedSameLossesOtherSeedOthers) {
  EXPECT_EQ(survivors(7), survivors(7));
  EXPECT_NE(survivors(7), survivors(8));
}

TEST(FaultInjectionTest, DelaysByWholeTicksKeepingOrder) {
  InProcessTransport bus;
  FaultConfig f;
  f.topics["/slow"].delay_ticks = 2;
  f.topics["/fast"].delay_ticks = 1;
  bus.set_faults(f);
  std::vector<std::pair<std::string, int>> got;
  bus.subscribe<msg::Clock>("/slow", [&](const msg::Clock& m) { got.emplace_back("slow", m.clock.sec); });
  bus.subscribe<msg::Clock>("/fast", [&](const msg::Clock& m) { got.emplace_back("fast", m.clock.sec); });
  auto slow = bus.advertise<msg::Clock>("/slow");
  auto fast = bus.advertise<msg::Clock>("/fast");
  bus.advance_to(10);
  msg::Clock m{{1, 0}};
  slow.publish(m);  // due at 12
  m.clock.sec = 2;
  fast.publish(m);  // due at 11
  m.clock.sec = 3;  // the transport holds its own copy: changing ours changes nothing
  EXPECT_TRUE(got.empty());
  bus.advance_to(11);
  ASSERT_EQ(got.size(), 1u);
  EXPECT_EQ(got[0], (std::pair<std::string, int>{"fast", 2}));
  fast.publish(m);  // published during 11: due at 12, after the slow one published earlier
  bus.advance_to(12);
  ASSERT_EQ(got.size(), 3u);
  EXPECT_EQ(got[1], (std::pair<std::string, int>{"slow", 1}));
  EXPECT_EQ(got[2], (std::pair<std::string, int>{"fast", 3}));
}

// Hover at 1 m under faults between plant and controller.
// With delayed sensor topics the controller's first step (tick 0) has no data yet and sends the
// stale-data safety command, as Algorithm 1 says: a start-up transient (a dip of a few cm, slowly
// recovered by the PD altitude loop). Hover is judged over the whole run and after 10 s.
constexpr Tick kSettleTicks = 1000;

struct HoverRun {
  std::vector<model::State> states;
  std::vector<model::Vector4> applied;
  int safety_ticks = 0;
  std::uint64_t dropped_commands = 0, dropped_imu = 0, watchdog_trips = 0;
  std::vector<msg::PlantStatus> plant_status;  ///< as published on /drone/plant_status
};

HoverRun hover(const FaultConfig& faults, Tick ticks) {
  SimulationConfig cfg;
  cfg.duration_ticks = ticks;
  cfg.faults = faults;
  control::ControllerConfig controller = controllers::make_config("paper", model::VehicleParams{});
  controller.node.setpoint.p_des_W.z() = 1.0;
  const model::State x0 = model::Quadrotor(controller.vehicle).initial_state({0, 0, 1.0}, 0.0, true);
  Simulation s(cfg, controller.vehicle, x0, controller, {});
  HoverRun r;
  s.transport().subscribe<msg::PlantStatus>(Topics::for_namespace(cfg.ns).plant_status,
                                            [&](const msg::PlantStatus& m) { r.plant_status.push_back(m); });
  s.run([&](const TickRecord& rec) {
    r.states.push_back(rec.state);
    r.applied.push_back(rec.latched_command);
    r.safety_ticks += rec.status.safety && rec.tick >= kSettleTicks ? 1 : 0;
  });
  const Topics t = Topics::for_namespace(cfg.ns);
  r.dropped_commands = s.dropped(t.motor_commands);
  r.dropped_imu = s.dropped(t.imu);
  r.watchdog_trips = s.plant().stats().watchdog_trips;
  return r;
}

FaultConfig lossy(std::uint64_t seed) {
  FaultConfig f;
  f.seed = seed;
  const Topics t = Topics::for_namespace("/drone");
  for (const std::string* name : {&t.pose, &t.velocity, &t.imu, &t.motor_commands}) {
    f.topics[*name] = {0.10, 1};  // 10 % loss, one tick (10 ms, at least 5 ms) late
  }
  return f;
}

TEST(FaultInjectionTest, HoverHoldsUnderTenPercentLossAndATickOfDelay) {
  constexpr Tick kTicks = 2000;  // 20 s
  const HoverRun clean = hover({}, kTicks);
  const HoverRun r = hover(lossy(3), kTicks);
  // The faults did act: about 10 % of the 1000 commands and 2000 IMU samples were lost.
  EXPECT_NEAR(static_cast<double>(r.dropped_commands), 100.0, 50.0);
  EXPECT_NEAR(static_cast<double>(r.dropped_imu), 200.0, 70.0);
  double start_dz = 0.0;  // the whole run, start-up transient included
  for (const auto& x : r.states) start_dz = std::max(start_dz, std::abs(x.p_W.z() - 1.0));
  EXPECT_LT(start_dz, 0.10);
  double max_dz = 0.0, max_xy = 0.0, max_tilt = 0.0;
  for (std::size_t k = kSettleTicks; k < r.states.size(); ++k) {
    const model::State& x = r.states[k];
    ASSERT_TRUE(x.p_W.allFinite());
    max_dz = std::max(max_dz, std::abs(x.p_W.z() - 1.0));
    max_xy = std::max(max_xy, x.p_W.head<2>().norm());
    const Eigen::Vector3d z_B = x.q_WB * Eigen::Vector3d::UnitZ();
    max_tilt = std::max(max_tilt, std::acos(std::min(1.0, z_B.z())));
  }
  // Bounds stated in docs/reliability.md: from 10 s on within 1 mm of 1 m, no drift, level.
  EXPECT_LT(max_dz, 0.001);
  EXPECT_LT(max_xy, 0.01);
  EXPECT_LT(max_tilt, 0.01);
  // Neither the stale-data safety (0.1 s) nor the plant's watchdog (0.5 s) was needed.
  EXPECT_EQ(r.safety_ticks, 0);
  EXPECT_EQ(r.watchdog_trips, 0u);
  // Commands stay near the hover speed (4830.6 rad/s), as without faults.
  const double hover_w = model::VehicleParams{}.hover_omega_rad_s();
  double dev = 0.0, dev_clean = 0.0;
  for (std::size_t k = kSettleTicks; k < r.applied.size(); ++k) {
    dev = std::max(dev, (r.applied[k].array() - hover_w).abs().maxCoeff());
    dev_clean = std::max(dev_clean, (clean.applied[k].array() - hover_w).abs().maxCoeff());
  }
  std::printf(
      "hover under 10 %% loss + 1 tick delay: max |z - 1| %.3f m from the start, from 10 s on: %.2e m, max xy %.2e m, "
      "max tilt %.2e rad, "
      "max |omega - hover| %.1f rad/s (%.1f without faults)\n",
      start_dz, max_dz, max_xy, max_tilt, dev, dev_clean);
  EXPECT_LT(dev, 0.01 * hover_w);
}

TEST(FaultInjectionTest, FaultyRunsAreDeterministicAndFaultsChangeTheRun) {
  const HoverRun a = hover(lossy(11), 600), b = hover(lossy(11), 600), c = hover(lossy(12), 600);
  ASSERT_EQ(a.applied.size(), b.applied.size());
  bool differs = false;
  for (std::size_t k = 0; k < a.applied.size(); ++k) {
    ASSERT_EQ(std::memcmp(a.applied[k].data(), b.applied[k].data(), sizeof(double) * 4), 0) << k;
    ASSERT_EQ(std::memcmp(a.states[k].p_W.data(), b.states[k].p_W.data(), sizeof(double) * 3), 0) << k;
    differs = differs || a.applied[k] != c.applied[k];
  }
  EXPECT_TRUE(differs) << "another seed should lose other messages";
}

TEST(FaultInjectionTest, TotalCommandLossEngagesTheWatchdogWhichStopsTheMotors) {
  FaultConfig f;
  f.topics["/drone/motor_commands"].drop_probability = 1.0;
  const HoverRun r = hover(f, 100);
  // The initial hover command acts until the 0.5 s limit at tick 50, then the motors stop.
  for (Tick k = 0; k < 50; ++k) EXPECT_GT(r.applied[k][0], 4000.0) << k;
  for (Tick k = 50; k <= 100; ++k) EXPECT_EQ(r.applied[k], model::Vector4::Zero()) << k;
  EXPECT_EQ(r.watchdog_trips, 1u);
  // The plant's status shows it from the next tick on (published with the outputs, before the latch).
  bool seen = false;
  for (const auto& st : r.plant_status) {
    const std::int64_t k = st.header.stamp.to_ns() / 10'000'000;
    EXPECT_EQ(st.watchdog_active, k >= 51) << "tick " << k;
    if (k == 51) {
      seen = true;
      EXPECT_EQ(st.watchdog_trips, 1u);
      EXPECT_EQ(st.watchdog_ticks, 1u);
    }
  }
  EXPECT_TRUE(seen) << "a status goes out on the tick the watchdog state changes";
  EXPECT_EQ(r.plant_status.back().watchdog_ticks, 50u);  // ticks 50..99 latched before tick 100's status
}

}  // namespace
}  // namespace quadcosim::sim
