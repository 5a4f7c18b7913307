// A plant that behaves as a Simulink plant simulation built to be driven step by step by a ROS 2
// controller (docs/simulink.md, "A Simulink plant driven by quadcosim's controller"): for each step k
// at the fixed step 0.01 s it publishes /clock, then Pose, Velocity and Imu stamped t_k (Publish
// blocks on every sample hit, /clock from a Publish block fed by the simulation time); on a control
// step (every 0.02 s) it blocks until a motor command arrives after that step's samples went out (a
// blocking receive on its command subscriber), takes the newest command, and integrates to t_k+1.
// It does not read the command's layout (a Simulink model uses the data only), so it is matched by
// arrival. The vehicle model is quadcosim's (sim::PlantNode on the DDS transport, labels ignored).
//
// Beyond Simulink, for the test: it waits until a controller is matched before step 0 and, until the
// first command came, publishes a step again when its command has not come within 0.5 s (discovery
// may lose the first samples); it reads each command's label only to count whether it answered the
// step it was taken for.
//
//   usage: waiting_plant SCENARIO TRAJECTORY_CSV [TIMEOUT_S]
// Writes the trajectory as quadcosim's trajectory.csv (no controller columns) and one JSON line:
// steps, commands taken, commands whose label was not the step's time (mismatched). Exit 0 done, 4
// when no controller or no command came within TIMEOUT_S (default 10), 2 on bad usage.
#include <chrono>
#include <cstdint>
#include <cstdio>
#include <exception>
#include <string>

#include "dds/dds_transport.hpp"
#include "hosts/scenario_resolvers.hpp"
#include "io/scenario.hpp"
#include "io/trajectory_csv.hpp"
#include "sim/messages.hpp"
#include "sim/plant_node.hpp"
#include "sim/topics.hpp"

int main(int argc, char** argv) try {
  using namespace quadcosim;
  if (argc < 3) {
    std::fprintf(stderr, "usage: waiting_plant SCENARIO TRAJECTORY_CSV [TIMEOUT_S]\n");
    return 2;
  }
  const io::Scenario sc = io::load_scenario(argv[1], hosts::scenario_resolvers());
  const auto timeout_ns = static_cast<std::int64_t>((argc > 3 ? std::stod(argv[3]) : 10.0) * 1e9);
  const sim::TickClock clock = sc.simulation.plant.clock;
  const sim::Topics topics = sim::Topics::for_namespace(sc.simulation.ns);

  dds::DdsTransport transport(dds::read_ros_environment());
  sim::PlantOptions po = sc.simulation.plant;
  po.drop_stale_commands = false;  // the layout is not read
  sim::PlantNode plant(transport, topics, sc.vehicle, po, io::initial_state(sc));
  // The test's own reader of the commands (a second DDS reader: it may take a command a moment after
  // the plant's reader did, so each step waits for both).
  std::int64_t newest_label_ns = -1;
  std::uint64_t labels_seen = 0;
  transport.subscribe<msg::Float64MultiArray>(topics.motor_commands, [&](const msg::Float64MultiArray& m) {
    newest_label_ns = msg::command_stamp_ns(m);
    ++labels_seen;
  });

  const bool matched = transport.spin_until(
      [&] {
        return transport.matched_writers(topics.motor_commands) > 0 && transport.matched_readers(topics.pose) > 0 &&
               transport.matched_readers(topics.velocity) > 0 && transport.matched_readers(topics.imu) > 0;
      },
      timeout_ns);
  if (!matched) {
    std::fprintf(stderr, "waiting_plant: no controller within the timeout\n");
    return 4;
  }

  io::TrajectoryWriter csv(argv[2]);
  long commands = 0, mismatched = 0;
  const sim::Tick last = sc.simulation.duration_ticks;
  for (sim::Tick k = 0; k <= last; ++k) {
    const std::uint64_t before = plant.command_receipt().received, labels_before = labels_seen;
    plant.publish_outputs(k);
    if (k % sc.simulation.controller_divider == 0) {
      const auto asked = std::chrono::steady_clock::now();
      auto last_ask = asked;
      while (plant.command_receipt().received <= before || labels_seen <= labels_before) {
        transport.spin_once(10'000'000);
        const auto now = std::chrono::steady_clock::now();
        if (now - asked > std::chrono::nanoseconds(timeout_ns)) {
          std::fprintf(stderr, "waiting_plant: no command for step %lld (t = %g s)\n", static_cast<long long>(k),
                       clock.seconds(k));
          return 4;
        }
        // Asked again only until the first command came: discovery may lose the first samples, but
        // once commands flow the samples are delivered (reliable), and a step asked twice under load
        // got two answers, the late one taken for the next step's (seen once under load: 4 of 751 off).
        if (commands == 0 && now - last_ask > std::chrono::milliseconds(500)) {
          plant.publish_outputs(k);
          last_ask = now;
        }
      }
      ++commands;
      if (newest_label_ns != clock.ns(k)) ++mismatched;
    }
    plant.latch_command(k);
    csv.write(clock.seconds(k), plant.state(), plant.latched_command(), io::ControlColumns::none(),
              plant.watchdog_active());
    if (k < last) plant.integrate(k);
  }
  csv.close();
  std::printf("{\"steps\": %lld, \"commands\": %ld, \"mismatched\": %ld}\n", static_cast<long long>(last + 1), commands,
              mismatched);
  return 0;
} catch (const std::exception& e) {
  std::fprintf(stderr, "waiting_plant: %s\n", e.what());
  return 2;
}
