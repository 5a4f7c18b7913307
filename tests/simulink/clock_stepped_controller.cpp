// A controller that behaves as a Simulink-generated ROS 2 node with "Enable ROS 2 time model
// stepping" (docs/simulink.md): it executes one model step when /clock publishes a time that is a
// multiple of the model's base rate (here the control period, 0.02 s), and its Subscribe blocks give
// that step the newest message received on each topic (no waiting, no matching of stamps). Its
// Publish block sends the rotor speeds as std_msgs/Float64MultiArray with an empty layout: no tick
// label. The control law is the scenario's controller (the paper's) run by a sim::ControllerNode on
// a private in-process bus: each DDS sample is forwarded there as it arrives, and a sample hit
// steps it at the /clock time, so what it computes depends only on which samples it held then.
//
// Samples and /clock are delivered in arrival order (dds::ArrivalExecutor: on Cyclone's receive
// thread, one at a time), as a node that takes each message when it comes. /clock is subscribed best
// effort with depth 1 (rclcpp's clock QoS), the sensors reliable with depth 1 (the newest only).
// A /clock time that is not later than the last step (a lockstep plant asking again) steps nothing.
//
//   usage: clock_stepped_controller SCENARIO STEPS_CSV [IDLE_S]
// Runs until no /clock has come for IDLE_S seconds (default 3) after the first one (30 s at most
// before it). STEPS_CSV gets one row per model step: the /clock time and the stamps of the Pose,
// Velocity and Imu it stepped on [ns] (-1: none yet). Prints one JSON line: clock messages, steps,
// steps on samples stamped other than the step's time (stale), non-hits ('-' in Simulink's
// /step_notify terms). Exit 0 when it stepped at least once, 1 otherwise, 2 on bad usage.
#include <chrono>
#include <cstdint>
#include <cstdio>
#include <exception>
#include <string>

#include "dds/arrival_executor.hpp"
#include "dds/dds_transport.hpp"
#include "hosts/scenario_resolvers.hpp"
#include "io/scenario.hpp"
#include "sim/controller_node.hpp"
#include "sim/inprocess_transport.hpp"
#include "sim/messages.hpp"
#include "sim/parameter_schedule.hpp"
#include "sim/topics.hpp"

int main(int argc, char** argv) try {
  using namespace quadcosim;
  if (argc < 3) {
    std::fprintf(stderr, "usage: clock_stepped_controller SCENARIO STEPS_CSV [IDLE_S]\n");
    return 2;
  }
  const io::Scenario sc = io::load_scenario(argv[1], hosts::scenario_resolvers());
  std::FILE* steps_csv = std::fopen(argv[2], "w");
  if (steps_csv == nullptr) {
    std::fprintf(stderr, "clock_stepped_controller: cannot write %s\n", argv[2]);
    return 2;
  }
  const double idle_s = argc > 3 ? std::stod(argv[3]) : 3.0;
  const sim::TickClock clock = sc.simulation.plant.clock;
  const std::int64_t base_rate_ns = clock.period_ns * sc.simulation.controller_divider;
  const double dt_s = static_cast<double>(base_rate_ns) / 1e9;
  const sim::Topics topics = sim::Topics::for_namespace(sc.simulation.ns);

  // The model: the scenario's controller on a private bus.
  sim::InProcessTransport model_bus;
  sim::ControllerNode model(model_bus, topics, sc.controller);
  sim::ParameterSchedule schedule(sc.schedule, clock);
  auto to_model_pose = model_bus.advertise<msg::PoseStamped>(topics.pose);
  auto to_model_velocity = model_bus.advertise<msg::TwistStamped>(topics.velocity);
  auto to_model_imu = model_bus.advertise<msg::Imu>(topics.imu);

  dds::DdsTransport transport(dds::read_ros_environment());
  transport.set_qos(topics.clock, {1, false});
  transport.set_qos(topics.pose, {1, true});
  transport.set_qos(topics.velocity, {1, true});
  transport.set_qos(topics.imu, {1, true});
  auto command_pub = transport.advertise<msg::Float64MultiArray>(topics.motor_commands);
  // The model's command, without its label: a Simulink Publish block sends the data it is given.
  model_bus.subscribe<msg::Float64MultiArray>(topics.motor_commands, [&](const msg::Float64MultiArray& m) {
    msg::Float64MultiArray out;
    out.data = m.data;
    command_pub.publish(out);
  });

  std::int64_t pose_ns = -1, velocity_ns = -1, imu_ns = -1;
  std::int64_t last_step_ns = -1;
  long clocks = 0, steps = 0, stale = 0, non_hits = 0, unmatched = 0;
  std::int64_t first_stale_ns = -1;
  auto last_clock = std::chrono::steady_clock::now();
  transport.subscribe<msg::PoseStamped>(topics.pose, [&](const msg::PoseStamped& m) {
    pose_ns = m.header.stamp.to_ns();
    to_model_pose.publish(m);
  });
  transport.subscribe<msg::TwistStamped>(topics.velocity, [&](const msg::TwistStamped& m) {
    velocity_ns = m.header.stamp.to_ns();
    to_model_velocity.publish(m);
  });
  transport.subscribe<msg::Imu>(topics.imu, [&](const msg::Imu& m) {
    imu_ns = m.header.stamp.to_ns();
    to_model_imu.publish(m);
  });
  transport.subscribe<msg::Clock>(topics.clock, [&](const msg::Clock& c) {
    ++clocks;
    last_clock = std::chrono::steady_clock::now();
    const std::int64_t t_ns = c.clock.to_ns();
    if (t_ns % base_rate_ns != 0) {  // not a sample hit of the base rate
      ++non_hits;
      return;
    }
    if (t_ns <= last_step_ns) return;  // that time again: stepped already
    // No step before the command publisher has matched the plant's reader: a command published
    // earlier would go nowhere, and the plant would wait for tick 0 in vain (it asks again, with
    // /clock, every 50 ms, so the first step comes with the first /clock after the match). Discovery
    // is asynchronous: the plant's readers may be known after its writers, under load by many ms.
    if (transport.matched_readers(topics.motor_commands) == 0) {
      ++unmatched;
      return;
    }
    last_step_ns = t_ns;
    ++steps;
    if (pose_ns != t_ns || velocity_ns != t_ns || imu_ns != t_ns) {
      ++stale;
      if (first_stale_ns < 0) first_stale_ns = t_ns;
    }
    std::fprintf(steps_csv, "%lld,%lld,%lld,%lld\n", static_cast<long long>(t_ns), static_cast<long long>(pose_ns),
                 static_cast<long long>(velocity_ns), static_cast<long long>(imu_ns));
    schedule.apply(model, t_ns);
    model.step(t_ns, dt_s);  // publishes the command (forwarded above)
  });

  {
    dds::ArrivalExecutor executor(transport);
    const auto start = std::chrono::steady_clock::now();
    const auto idle = std::chrono::duration<double>(idle_s);
    for (;;) {
      executor.wait(100'000'000);
      const auto now = std::chrono::steady_clock::now();
      if (clocks > 0 ? now - last_clock > idle : now - start > std::chrono::seconds(30)) break;
    }
  }
  std::fclose(steps_csv);
  std::fprintf(stderr, "clock_stepped_controller: %ld /clock sample hits skipped before the command writer matched\n",
               unmatched);
  std::printf(
      "{\"clock_messages\": %ld, \"steps\": %ld, \"stale_steps\": %ld, \"first_stale_s\": %g, \"non_hits\": %ld, "
      "\"last_step_s\": %g}\n",
      clocks, steps, stale, first_stale_ns < 0 ? -1.0 : static_cast<double>(first_stale_ns) / 1e9, non_hits,
      static_cast<double>(last_step_ns) / 1e9);
  return steps > 0 ? 0 : 1;
} catch (const std::exception& e) {
  std::fprintf(stderr, "clock_stepped_controller: %s\n", e.what());
  return 2;
}
