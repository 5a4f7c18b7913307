// Tests of the drivers without processes: the lockstep plant driver against a hand-written tick loop
// (the order of sim/steppable_plant.hpp written out here, independent of sim::LockstepCore, which
// both the drivers and the in-process Simulation run on) bit for bit, for one vehicle and for a
// swarm, with answers delivered synchronously and from a queue as over DDS (on delivery or on the
// host's thread); the one answer rule (labelled, unlabelled, repeats, statuses); timeouts, retries,
// hold and resume; the real-time plant driver's pacing; both controller drivers. The in-process
// Simulation is checked against the same loop.
#include <gtest/gtest.h>

#include <deque>
#include <functional>
#include <memory>
#include <stdexcept>
#include <vector>

#include "controllers/registry.hpp"
#include "drivers/controller_drivers.hpp"
#include "drivers/lockstep_plant_driver.hpp"
#include "drivers/realtime_plant_driver.hpp"
#include "sim/controller_node.hpp"
#include "sim/inprocess_transport.hpp"
#include "sim/parameter_schedule.hpp"
#include "sim/plant_node.hpp"
#include "sim/simulation.hpp"
#include "sim/swarm.hpp"

namespace quadcosim::drivers {
namespace {

using sim::Tick;

// The paper controller with its defaults, for the Table 1 vehicle.
control::ControllerConfig paper() { return controllers::make_config("paper", model::VehicleParams{}); }

bool same(const model::State& a, const model::State& b) {
  return a.p_W == b.p_W && a.v_W == b.v_W && a.q_WB.coeffs() == b.q_WB.coeffs() && a.w_B == b.w_B &&
         a.omega_rad_s == b.omega_rad_s;
}

std::vector<model::State> reference_run(const sim::SimulationConfig& sc, const model::State& x0,
                                        const control::ControllerConfig& c,
                                        const std::vector<sim::ScheduledParameter>& schedule) {
  sim::InProcessTransport bus;
  const sim::Topics t = sim::Topics::for_namespace(sc.ns);
  sim::PlantNode plant(bus, t, c.vehicle, sc.plant, x0);
  sim::ControllerNode node(bus, t, c);
  sim::ParameterSchedule changes(schedule, sc.plant.clock);
  const double dt_s = sc.plant.clock.period_s() * sc.controller_divider;
  std::vector<model::State> states;
  for (Tick k = 0; k <= sc.duration_ticks; ++k) {
    changes.apply(node, sc.plant.clock.ns(k));
    plant.publish_outputs(k);
    if (k % sc.controller_divider == 0) node.step(sc.plant.clock.ns(k), dt_s);
    plant.latch_command(k);
    states.push_back(plant.state());
    if (k < sc.duration_ticks) plant.integrate(k);
  }
  return states;
}

// A host on a fake clock: what the controllers publish waits in a queue until wait() delivers it
// (then on_delivery() runs, while delivery on arrival is on, as dds::ArrivalExecutor runs it on
// Cyclone's receive thread); when nothing is left, the time the wait allowed passes.
struct QueuedHost : DriverHost {
  std::int64_t clock_ns = 0;
  std::deque<std::function<void()>> queue;
  LockstepPlantDriver* driver = nullptr;
  bool on_arrival = false;
  bool in_delivery = false;  ///< inside on_delivery (the "receive thread")
  int waits = 0;
  bool stop = false;
  std::int64_t now_ns() override { return clock_ns; }
  bool stop_requested() override { return stop; }
  void wait(std::int64_t timeout_ns, const std::function<bool()>& woken) override {
    ++waits;
    while (!queue.empty()) {
      auto f = std::move(queue.front());
      queue.pop_front();
      f();
      bool wake = false;
      if (on_arrival && driver) {
        in_delivery = true;
        wake = driver->on_delivery();
        in_delivery = false;
      }
      if (wake || (woken && woken())) return;
    }
    if (woken && woken()) return;
    clock_ns += timeout_ns;
  }
  void deliver_on_arrival(bool on) override { on_arrival = on; }
};

// N vehicles as two processes over DDS: the plants on one bus, the controllers (LockstepStepper
// hooks, as `quadcosim controller`) on another. Sensor samples cross at once; commands and
// statuses through the host's queue, unless the vehicle's controller is `silent`.
struct Rig {
  sim::InProcessTransport plant_bus, controller_bus;
  std::vector<std::unique_ptr<sim::PlantNode>> plants;
  std::vector<std::unique_ptr<sim::ControllerNode>> controllers;
  std::unique_ptr<LockstepControllerDriver> controller_driver;
  std::vector<std::int64_t> status_stamp;
  std::vector<int> poses;  ///< Pose publications per vehicle
  std::vector<bool> silent;
  std::vector<sim::SwarmVehicle> setups;
  QueuedHost host;

  Rig(const sim::SimulationConfig& sc, int n, const std::vector<sim::ScheduledParameter>& schedule = {},
      bool drop_stale = true) {
    sim::SwarmLayout layout;
    layout.vehicles = n;
    const control::ControllerConfig cfg = paper();
    std::vector<DrivenController> driven;
    status_stamp.assign(static_cast<std::size_t>(n), -1);
    poses.assign(static_cast<std::size_t>(n), 0);
    silent.assign(static_cast<std::size_t>(n), false);
    for (int i = 0; i < n; ++i) {
      setups.push_back(sim::swarm_vehicle(sc, {}, cfg, schedule, layout, i));
      const sim::SwarmVehicle& v = setups.back();
      const sim::Topics t = sim::Topics::for_namespace(v.simulation.ns);
      sim::PlantOptions po = v.simulation.plant;
      po.drop_stale_commands = drop_stale;
      plants.push_back(std::make_unique<sim::PlantNode>(plant_bus, t, cfg.vehicle, po, v.initial));
      controllers.push_back(std::make_unique<sim::ControllerNode>(controller_bus, t, v.controller));
      driven.push_back({controllers.back().get(), v.schedule});
      relay<msg::PoseStamped>(t.pose, i, false);
      relay<msg::TwistStamped>(t.velocity, i, false);
      relay<msg::Imu>(t.imu, i, false);
      relay<msg::Float64MultiArray>(t.motor_commands, i, true);
      relay<msg::ControllerStatus>(t.controller_status, i, true);
      plant_bus.subscribe<msg::ControllerStatus>(
          t.controller_status, [this, i](const msg::ControllerStatus& m) { status_stamp[i] = m.header.stamp.to_ns(); });
      plant_bus.subscribe<msg::PoseStamped>(t.pose, [this, i](const msg::PoseStamped&) { ++poses[i]; });
    }
    controller_driver =
        std::make_unique<LockstepControllerDriver>(std::move(driven), sc.plant.clock, sc.controller_divider, host);
  }

  template <class T>
  void relay(const std::string& topic, int i, bool queued) {
    sim::Transport& from = queued ? static_cast<sim::Transport&>(controller_bus) : plant_bus;
    sim::Transport& to = queued ? static_cast<sim::Transport&>(plant_bus) : controller_bus;
    auto pub = std::make_shared<sim::Publisher<T>>(to.advertise<T>(topic));
    from.subscribe<T>(topic, [this, pub, queued, i](const T& m) {
      if (!queued) return pub->publish(m);
      if (silent[static_cast<std::size_t>(i)]) return;
      host.queue.push_back([pub, m] { pub->publish(m); });
    });
  }

  std::vector<DrivenPlant> driven(bool statuses) {
    std::vector<DrivenPlant> d;
    for (std::size_t i = 0; i < plants.size(); ++i) {
      DrivenPlant p{plants[i].get(), {}, {}};
      if (statuses) {
        p.status_awaited = [] { return true; };
        p.status_stamp_ns = [this, i] { return status_stamp[i]; };
      }
      d.push_back(std::move(p));
    }
    return d;
  }
};

LockstepOptions options_of(const sim::SimulationConfig& sc) {
  LockstepOptions o;
  o.clock = sc.plant.clock;
  o.duration_ticks = sc.duration_ticks;
  o.controller_divider = sc.controller_divider;
  o.timeout_ns = 1'000'000'000;
  return o;
}

struct Flight {
  LockstepResult result;
  std::vector<std::vector<model::State>> states;  ///< per vehicle, per tick
  int ticks_on_delivery = 0;                      ///< ticks latched inside on_delivery
};

Flight fly(Rig& rig, LockstepOptions o, LockstepHooks hooks = {}, bool statuses = true) {
  Flight f;
  f.states.resize(rig.plants.size());
  hooks.after_latch = [&, inner = hooks.after_latch](std::size_t i, Tick k) {
    f.states[i].push_back(rig.plants[i]->state());
    if (i == 0 && rig.host.in_delivery) ++f.ticks_on_delivery;
    if (inner) inner(i, k);
  };
  LockstepPlantDriver driver(rig.driven(statuses), o, std::move(hooks), rig.host);
  rig.host.driver = &driver;
  f.result = driver.run();
  EXPECT_FALSE(rig.host.on_arrival) << "delivery on arrival left on";
  return f;
}

const std::vector<sim::ScheduledParameter> kSchedule = {{50, "z_des", 1.0}, {121, "yaw_des", 0.3}};

sim::SimulationConfig config(Tick ticks) {
  sim::SimulationConfig sc;
  sc.duration_ticks = ticks;
  return sc;
}

// The in-process Simulation (sim::LockstepCore over a synchronous host) against the same loop.
TEST(SimulationOnTheLockstepCoreTest, FliesTheHandWrittenLoopsBits) {
  const sim::SimulationConfig sc = config(300);
  const auto expected = reference_run(sc, {}, paper(), kSchedule);
  sim::Simulation s(sc, model::VehicleParams{}, {}, paper(), kSchedule);
  std::size_t i = 0, differ = 0;
  s.run([&](const sim::TickRecord& r) {
    if (i >= expected.size() || !same(r.state, expected[i])) ++differ;
    ++i;
  });
  EXPECT_EQ(i, expected.size());
  EXPECT_EQ(differ, 0u);
  EXPECT_GT(expected.back().p_W.z(), 0.5);  // it climbed toward z_des = 1 m
}

TEST(LockstepPlantDriverTest, OneVehicleFliesTheSimulationsBitsWithTicksRunOnDelivery) {
  const sim::SimulationConfig sc = config(300);
  const auto expected = reference_run(sc, {}, paper(), kSchedule);
  Rig rig(sc, 1, kSchedule);
  const Flight f = fly(rig, options_of(sc));
  ASSERT_EQ(f.result, LockstepResult::kDone);
  ASSERT_EQ(f.states[0].size(), expected.size());
  EXPECT_GT(expected.back().p_W.z(), 0.5);  // it climbed: the schedule acted
  for (std::size_t k = 0; k < expected.size(); ++k) ASSERT_TRUE(same(f.states[0][k], expected[k])) << "tick " << k;
  // Every tick ran where the answer completing its control period was delivered.
  EXPECT_EQ(f.ticks_on_delivery, static_cast<int>(expected.size()));
  EXPECT_EQ(rig.poses[0], static_cast<int>(expected.size()));  // nobody was asked twice
}

TEST(LockstepPlantDriverTest, ASwarmShareFliesEachVehiclesOwnSimulationOnTheHostsThread) {
  const sim::SimulationConfig sc = config(120);
  Rig rig(sc, 3, kSchedule);
  LockstepOptions o = options_of(sc);
  o.ticks_on_delivery = false;
  const Flight f = fly(rig, o);
  ASSERT_EQ(f.result, LockstepResult::kDone);
  EXPECT_EQ(f.ticks_on_delivery, 0);
  for (int i = 0; i < 3; ++i) {
    const sim::SwarmVehicle& v = rig.setups[static_cast<std::size_t>(i)];
    const auto expected = reference_run(v.simulation, v.initial, v.controller, v.schedule);
    const auto& got = f.states[static_cast<std::size_t>(i)];
    ASSERT_EQ(got.size(), expected.size());
    for (std::size_t k = 0; k < expected.size(); ++k) ASSERT_TRUE(same(got[k], expected[k])) << i << " tick " << k;
  }
  EXPECT_NE(f.states[1].back().p_W.x(), f.states[0].back().p_W.x());  // the vehicles fly apart
}

// A controller that answers every control tick at once with an unlabelled command (as a foreign ROS
// node might), or (stale_first) tick 0's labelled command for every tick.
struct PlainController {
  sim::InProcessTransport bus;
  sim::Topics t = sim::Topics::for_namespace("/drone");
  std::unique_ptr<sim::PlantNode> plant;
  sim::Publisher<msg::Float64MultiArray> pub = bus.advertise<msg::Float64MultiArray>(t.motor_commands);
  bool stale_first = false;
  bool answer = true;
  std::int64_t first_answer_ns = 0;  ///< answers no sample stamped earlier (a timer on ROS time: one period)
  int answered = 0;
  explicit PlainController(bool drop_stale) {
    sim::PlantOptions po;
    po.drop_stale_commands = drop_stale;
    bus.subscribe<msg::Imu>(t.imu, [this](const msg::Imu& m) {
      const std::int64_t s = m.header.stamp.to_ns();
      if (!answer || s % 20'000'000 != 0 || s < first_answer_ns) return;
      msg::Float64MultiArray c;
      if (stale_first) {  // tick 0's command, labelled, and for every later tick that one again
        c.dim.push_back({msg::command_label(0), 4, 1});
        c.data = {1, 1, 1, 1};
        pub.publish(c);
        return;
      }
      c.data = {100.0 + static_cast<double>(s / 20'000'000), 100, 100, 100};
      pub.publish(c);
      ++answered;
    });
    plant = std::make_unique<sim::PlantNode>(bus, t, model::VehicleParams{}, po, model::State{});
  }
};

TEST(LockstepPlantDriverTest, AnUnlabelledCommandAnswersTheTickItArrivesAfter) {
  PlainController c(true);
  QueuedHost host;
  LockstepOptions o;
  o.duration_ticks = 10;
  LockstepPlantDriver driver({DrivenPlant{c.plant.get(), {}, {}}}, o, {}, host);
  host.driver = &driver;
  ASSERT_EQ(driver.run(), LockstepResult::kDone);
  EXPECT_EQ(c.answered, 6);                       // ticks 0, 2, ..., 10
  EXPECT_EQ(c.plant->latched_command()[0], 105);  // tick 10's own command acts at tick 10
  EXPECT_EQ(host.clock_ns, 0) << "the driver waited for an answer that was there";
}

TEST(LockstepPlantDriverTest, AControllerOnATimerIsFirstAwaitedOnePeriodIn) {
  // A timer on ROS time first fires one control period after it starts: no answer to tick 0.
  PlainController c(true);
  c.first_answer_ns = 20'000'000;
  QueuedHost host;
  LockstepOptions o;
  o.duration_ticks = 10;
  o.timeout_ns = 200'000'000;
  o.first_control_tick = 2;
  std::vector<double> latched;
  LockstepHooks h;
  h.after_latch = [&](std::size_t, Tick) { latched.push_back(c.plant->latched_command()[0]); };
  LockstepPlantDriver driver({DrivenPlant{c.plant.get(), {}, {}}}, o, h, host);
  host.driver = &driver;
  ASSERT_EQ(driver.run(), LockstepResult::kDone);
  EXPECT_EQ(c.answered, 5);  // ticks 2, 4, ..., 10
  EXPECT_EQ(host.clock_ns, 0) << "the driver waited for an answer to a tick before the first";
  ASSERT_EQ(latched.size(), 11u);
  EXPECT_EQ(latched[0], 0);  // no command yet: the plant's initial one
  EXPECT_EQ(latched[1], 0);
  EXPECT_EQ(latched[2], 101);  // tick 2's own command acts at tick 2
  EXPECT_EQ(latched[10], 105);

  // Awaited from tick 0 (the default), the same controller leaves tick 0 unanswered.
  PlainController late(true);
  late.first_answer_ns = 20'000'000;
  QueuedHost host2;
  o.first_control_tick = 0;
  LockstepPlantDriver waiting({DrivenPlant{late.plant.get(), {}, {}}}, o, {}, host2);
  host2.driver = &waiting;
  EXPECT_EQ(waiting.run(), LockstepResult::kTimedOut);
  EXPECT_EQ(waiting.ticks_run(), 0);
}

TEST(LockstepPlantDriverTest, ALabelledRepeatOfAnEarlierTickIsNoAnswer) {
  PlainController c(true);
  c.stale_first = true;  // tick 2's only command is labelled with tick 0: a repeat
  QueuedHost host;
  LockstepOptions o;
  o.duration_ticks = 4;
  o.timeout_ns = 200'000'000;
  int timeouts = 0;
  Tick timed_out = -1;
  LockstepHooks h;
  h.on_timeout = [&](std::size_t i, Tick k) {
    ++timeouts;
    timed_out = k;
    EXPECT_EQ(i, 0u);
  };
  LockstepPlantDriver driver({DrivenPlant{c.plant.get(), {}, {}}}, o, std::move(h), host);
  EXPECT_EQ(driver.run(), LockstepResult::kTimedOut);
  EXPECT_EQ(timeouts, 1);
  EXPECT_EQ(timed_out, 2);
  EXPECT_EQ(driver.ticks_run(), 2);
  EXPECT_GE(c.plant->stats().commands_stale, 1u);
}

TEST(LockstepPlantDriverTest, AwaitsTheStatusOfTheTickWhenAsked) {
  const sim::SimulationConfig sc = config(20);
  Rig rig(sc, 1);
  // The command comes, but with the status awaited and none of the tick's own, tick 0 never completes.
  LockstepOptions o = options_of(sc);
  int status_asks = 0;
  std::vector<DrivenPlant> d = rig.driven(true);
  d[0].status_stamp_ns = [&] {
    ++status_asks;
    return rig.status_stamp[0] - 1;  // never the tick's own stamp
  };
  LockstepPlantDriver driver(std::move(d), o, {}, rig.host);
  rig.host.driver = &driver;
  EXPECT_EQ(driver.run(), LockstepResult::kTimedOut);
  EXPECT_EQ(driver.ticks_run(), 0);
  EXPECT_GT(status_asks, 0);
}

TEST(LockstepPlantDriverTest, AsksAgainEveryRetryPeriodThenTimesOutUnderAbort) {
  const sim::SimulationConfig sc = config(100);
  Rig rig(sc, 3);
  rig.silent[1] = true;  // vehicle 1's controller never answers
  LockstepOptions o = options_of(sc);
  o.timeout_ns = 200'000'000;
  o.retry_ns = 50'000'000;
  std::vector<std::size_t> late;
  LockstepHooks h;
  h.on_timeout = [&](std::size_t i, Tick k) {
    late.push_back(i);
    EXPECT_EQ(k, 0);
  };
  const Flight f = fly(rig, o, std::move(h));
  EXPECT_EQ(f.result, LockstepResult::kTimedOut);
  EXPECT_EQ(late, std::vector<std::size_t>{1});
  // Asked at 0 and again at 50, 100, 150 ms; the others, answered, only once.
  EXPECT_EQ(rig.poses, (std::vector<int>{1, 4, 1}));
  EXPECT_EQ(rig.host.clock_ns, 200'000'000);
  EXPECT_TRUE(f.states[0].empty());
}

TEST(LockstepPlantDriverTest, UnderHoldItGoesOnAndResumesWhenCommandsComeBack) {
  const sim::SimulationConfig sc = config(200);
  Rig rig(sc, 1);
  LockstepOptions o = options_of(sc);
  o.on_timeout = TimeoutPolicy::kHold;
  o.timeout_ns = 300'000'000;
  Tick resumed = -1;
  int timeouts = 0;
  LockstepHooks h;
  // The controller falls silent from tick 40 to tick 120 (of the plant's ticks).
  h.after_latch = [&](std::size_t, Tick k) { rig.silent[0] = k >= 39 && k < 119; };
  h.on_timeout = [&](std::size_t, Tick k) {
    ++timeouts;
    EXPECT_EQ(k, 40);
  };
  h.on_resume = [&](Tick k) { resumed = k; };
  const Flight f = fly(rig, o, std::move(h), false);
  EXPECT_EQ(f.result, LockstepResult::kDone);
  EXPECT_EQ(timeouts, 1);  // one timeout, not one per tick
  EXPECT_EQ(resumed, 120);
  ASSERT_EQ(f.states[0].size(), 201u);
  EXPECT_GT(rig.plants[0]->stats().watchdog_trips, 0u);  // held past the watchdog's 0.5 s: it acted
}

TEST(LockstepPlantDriverTest, ATickThatNeedsTheHostsThreadIsRunThereAndARefusalEndsTheRun) {
  const sim::SimulationConfig sc = config(40);
  Rig rig(sc, 1);
  LockstepOptions o = options_of(sc);
  std::vector<Tick> on_host;
  LockstepHooks h;
  h.main_thread_due = [](Tick k) { return k == 10 || k == 25; };
  h.before_outputs = [&](Tick k) {
    if (k == 10 || k == 25) {
      EXPECT_FALSE(rig.host.in_delivery) << "tick " << k;
      on_host.push_back(k);
    }
    return k != 25;
  };
  const Flight f = fly(rig, o, std::move(h));
  EXPECT_EQ(f.result, LockstepResult::kRefused);
  EXPECT_EQ(on_host, (std::vector<Tick>{10, 25}));
  EXPECT_EQ(f.states[0].size(), 25u);
}

TEST(LockstepPlantDriverTest, AStopEndsTheRunAtATickBoundary) {
  const sim::SimulationConfig sc = config(100);
  Rig rig(sc, 1);
  LockstepHooks h;
  h.after_latch = [&](std::size_t, Tick k) { rig.host.stop = k == 30; };
  const Flight f = fly(rig, options_of(sc), std::move(h));
  EXPECT_EQ(f.result, LockstepResult::kStopped);
  EXPECT_EQ(f.states[0].size(), 31u);
}

TEST(RealtimePlantDriverTest, RunsEveryTickOnTheWallClockAndCountsLateTicks) {
  sim::InProcessTransport bus;
  const sim::Topics t = sim::Topics::for_namespace("/drone");
  sim::PlantNode plant(bus, t, model::VehicleParams{}, sim::PlantOptions{}, model::State{});
  struct Clock : DriverHost {
    std::int64_t ns = 1'000;
    int waits = 0;
    std::int64_t now_ns() override { return ns; }
    void wait(std::int64_t timeout_ns, const std::function<bool()>&) override {
      ++waits;
      ns += timeout_ns;
      if (waits == 5) ns += 25'000'000;  // one stall of 2.5 plant periods (at 2x: 5 periods)
    }
  } host;
  RealtimeOptions o;
  o.duration_ticks = 20;
  o.rate_factor = 2.0;
  int refused_at = -1;
  RealtimeHooks h;
  h.before_outputs = [&](Tick k) { return k != 15 || (refused_at = 15, false); };
  RealtimePlantDriver driver({&plant}, o, std::move(h), host);
  EXPECT_EQ(driver.run(), RealtimeResult::kRefused);
  EXPECT_EQ(refused_at, 15);
  EXPECT_EQ(driver.ticks_run(), 15);
  EXPECT_EQ(driver.max_late_ns(), 25'000'000);
  // The stall made its tick 25 ms late (> one 5 ms wall period) and the next four, which found their
  // wall time already past, 20, 15, 10 and 5 ms late (the last not more than one period).
  EXPECT_EQ(driver.late_ticks(), 4);
  EXPECT_EQ(host.ns, 1'000 + 15 * 5'000'000);  // tick 14 ended on its wall time
}

TEST(LockstepControllerDriverTest, StepsOnDeliveryUntilAStop) {
  sim::InProcessTransport bus;
  const sim::Topics t = sim::Topics::for_namespace("/drone");
  sim::PlantNode plant(bus, t, model::VehicleParams{}, sim::PlantOptions{}, model::State{});
  sim::ControllerNode node(bus, t, paper());
  struct Host : DriverHost {
    sim::PlantNode& plant;
    Tick k = 0;
    bool arrival = false;
    explicit Host(sim::PlantNode& p) : plant(p) {}
    std::int64_t now_ns() override { return 0; }
    void wait(std::int64_t, const std::function<bool()>&) override { plant.publish_outputs(k++); }
    bool stop_requested() override { return k == 7; }
    void deliver_on_arrival(bool on) override { arrival = on; }
  } host(plant);
  {
    LockstepControllerDriver driver({{&node, {{4, "z_des", 2.0}}}}, sim::TickClock{}, 2, host);
    driver.run();
    EXPECT_FALSE(host.arrival);
  }
  EXPECT_EQ(node.last_step_ns(), 60'000'000);  // ticks 0, 2, 4, 6 stepped
  EXPECT_EQ(node.settings().setpoint.p_des_W.z(), 2.0);
  plant.publish_outputs(8);  // the driver is gone: its hooks too
  EXPECT_EQ(node.last_step_ns(), 60'000'000);
}

TEST(RealtimeControllerDriverTest, CommandsNothingBeforeTheFirstCompleteSample) {
  sim::InProcessTransport bus;
  const sim::Topics t = sim::Topics::for_namespace("/drone");
  int commands = 0;
  bus.subscribe<msg::Float64MultiArray>(t.motor_commands, [&](const msg::Float64MultiArray&) { ++commands; });
  sim::PlantNode plant(bus, t, model::VehicleParams{}, sim::PlantOptions{}, model::State{});
  sim::ControllerNode node(bus, t, paper());
  struct Host : DriverHost {
    std::int64_t ns = 0;
    int wakes = 0;
    std::function<void(int)> at_wake;
    std::int64_t now_ns() override { return ns; }
    void wait(std::int64_t, const std::function<bool()>&) override {}
    void wait_until(std::int64_t deadline_ns) override {
      ns = deadline_ns;
      at_wake(++wakes);
    }
    bool stop_requested() override { return wakes >= 6; }
  } host;
  host.at_wake = [&](int w) {
    if (w >= 3) plant.publish_outputs(w);  // the plant shows up before the third wake-up
  };
  std::vector<std::int64_t> first, wakes;
  RealtimeControllerHooks h;
  h.on_wake = [&](std::int64_t now) { wakes.push_back(now); };
  h.on_first_sample = [&](std::size_t i, std::int64_t stamp) {
    EXPECT_EQ(i, 0u);
    first.push_back(stamp);
  };
  RealtimeControllerDriver driver({{&node, {}}}, sim::TickClock{}, 2, 4.0, std::move(h), host);
  driver.run();
  EXPECT_EQ(first, std::vector<std::int64_t>{30'000'000});
  EXPECT_EQ(commands, 4);  // wake-ups 3..6
  EXPECT_EQ(wakes, (std::vector<std::int64_t>{5'000'000, 10'000'000, 15'000'000, 20'000'000, 25'000'000, 30'000'000}));
}

}  // namespace
}  // namespace quadcosim::drivers
