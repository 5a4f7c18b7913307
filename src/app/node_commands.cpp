// `quadcosim plant` and `quadcosim controller`: the two nodes as long-running processes over DDS,
// in lockstep (deterministic, as fast as the pair can go) or in real time.
#include <fmt/format.h>

#include <algorithm>
#include <chrono>
#include <filesystem>
#include <vector>
#include <iostream>
#include <memory>
#include <optional>

#include "app/commands.hpp"
#include "app/parameter_binding.hpp"
#include "app/signals.hpp"
#include "control/care.hpp"
#include "dds/dds_transport.hpp"
#include "dds/node_announcer.hpp"
#include "dds/parameter_client.hpp"
#include "io/mcap_recorder.hpp"
#include "io/scenario.hpp"
#include "io/trajectory_csv.hpp"
#include "sim/controller_node.hpp"
#include "sim/plant_node.hpp"

namespace quadcosim::app {

namespace {

std::int64_t steady_ns() {
  return std::chrono::duration_cast<std::chrono::nanoseconds>(
             std::chrono::steady_clock::now().time_since_epoch())
      .count();
}

constexpr std::int64_t kMs = 1'000'000;

// The scenario (or the defaults), with its vehicle replaced by `vehicle_file` when one is given.
io::Scenario scenario_or_defaults(const std::string& path, const std::string& vehicle_file) {
  io::Scenario sc;
  if (!path.empty()) {
    sc = io::load_scenario(path);
  } else {
    sc.name = "defaults";
  }
  if (!vehicle_file.empty()) sc.vehicle = io::load_vehicle(vehicle_file);
  sc.controller.params.vehicle = sc.vehicle;
  return sc;
}

// ROS sensor-data QoS (KEEP_LAST 5, BEST_EFFORT) on the three sensor topics.
void use_sensor_qos(dds::DdsTransport& transport, const sim::Topics& topics) {
  for (const auto* t : {&topics.pose, &topics.velocity, &topics.imu}) {
    transport.set_qos(*t, dds::QosProfile::sensor_data());
  }
}

}  // namespace

int plant_command(const PlantCommandOptions& o) {
  install_stop_handlers();
  try {
    io::Scenario sc = scenario_or_defaults(o.scenario, o.vehicle);
    if (!o.ns.empty()) sc.simulation.ns = o.ns;
    if (o.duration_s >= 0.0) {
      sc.simulation.duration_ticks =
          static_cast<sim::Tick>(o.duration_s / sc.simulation.plant.clock.period_s() + 0.5);
    }
    const sim::TickClock clock = sc.simulation.plant.clock;
    const int divider = sc.simulation.controller_divider;
    const sim::Topics topics = sim::Topics::for_namespace(sc.simulation.ns);

    dds::DdsTransport transport(dds::read_ros_environment(o.enclave));
    if (o.sensor_qos) use_sensor_qos(transport, topics);
    sim::PlantOptions po = sc.simulation.plant;
    po.drop_stale_commands = o.lockstep;
    sim::PlantNode plant(transport, topics, sc.vehicle, po, io::initial_state(sc));
    msg::ControllerStatus status;
    status.header.stamp = msg::Time::from_ns(-1);
    bool have_status = false;
    transport.subscribe<msg::ControllerStatus>(topics.controller_status, [&](const msg::ControllerStatus& m) {
      status = m;
      have_status = true;
    });
    std::unique_ptr<io::TrajectoryWriter> csv;
    if (!o.record.empty()) csv = std::make_unique<io::TrajectoryWriter>(o.record);
    std::unique_ptr<io::McapRecorder> mcap;
    if (!o.mcap.empty()) mcap = std::make_unique<io::McapRecorder>(o.mcap, transport, topics);
    auto record = [&](sim::Tick k) {
      if (csv) {
        csv->write(clock.seconds(k), plant.state(), plant.applied_command(),
                   have_status ? io::ControlColumns::from(status) : io::ControlColumns::none());
      }
    };

    dds::NodeAnnouncer announcer(transport.participant().handle(), "quadrotor_plant");
    announcer.announce();  // `ros2 node list` shows /quadrotor_plant
    std::cerr << fmt::format("plant: domain {}, namespace {}, {} mode, {} ticks of {} s\n",
                             transport.participant().domain_id(), sc.simulation.ns,
                             o.lockstep ? "lockstep" : "real-time", sc.simulation.duration_ticks,
                             clock.period_s());
    if (o.lockstep || o.wait_for_controller) {
      // Wait until a controller is there to answer, so tick 0 is not published into the void.
      const bool found = transport.spin_until(
          [&] {
            // The recorder's own readers (same participant) match too: look for one more.
            const int own = mcap ? 1 : 0;
            return stop_requested() || (transport.matched_writers(topics.motor_commands) > 0 &&
                                        transport.matched_readers(topics.pose) > own &&
                                        transport.matched_readers(topics.velocity) > own &&
                                        transport.matched_readers(topics.imu) > own);
          },
          static_cast<std::int64_t>(o.timeout_s * 1e9));
      if (!found) {
        std::cerr << fmt::format("plant: no controller on {} within {} s (matched command writers: {}, "
                                 "pose readers: {}); is it running on ROS_DOMAIN_ID {}?\n",
                                 topics.motor_commands, o.timeout_s, transport.matched_writers(topics.motor_commands),
                                 transport.matched_readers(topics.pose), transport.participant().domain_id());
        return 4;
      }
    }

    const std::int64_t loop_start = steady_ns();
    std::int64_t next_wall = loop_start;
    const auto period_wall = static_cast<std::int64_t>(static_cast<double>(clock.period_ns) / o.rate_factor);
    // Under the hold policy a timeout switches waiting off until a command arrives again, so a
    // vanished controller costs one timeout, not one per tick.
    bool waiting = true;
    std::vector<std::int64_t> round_trip_ns;  // lockstep: sensor publication -> command back
    round_trip_ns.reserve(static_cast<std::size_t>(sc.simulation.duration_ticks / divider + 1));
    // The schedule through the controller's parameter services: each change is acknowledged before
    // the tick it is due at is published, so the run stays deterministic.
    std::unique_ptr<dds::ParameterClient> scheduler;
    if (!o.schedule_node.empty()) {
      scheduler = std::make_unique<dds::ParameterClient>(transport.participant().handle(),
                                                         dds::parse_node_name(o.schedule_node));
    }
    auto next_event = sc.schedule.begin();
    for (sim::Tick k = 0; k <= sc.simulation.duration_ticks && !stop_requested(); ++k) {
      const std::int64_t t_ns = clock.ns(k);
      for (; scheduler && next_event != sc.schedule.end() && next_event->tick <= k; ++next_event) {
        const auto r = scheduler->set({{next_event->name, to_ros(next_event->value)}},
                                      static_cast<std::int64_t>(o.timeout_s * 1e9));
        if (r.size() != 1 || !r[0].successful) {
          std::cerr << fmt::format("plant: scheduled {} at t = {} s refused by {}: {}\n", next_event->name,
                                   clock.seconds(k), o.schedule_node, r.empty() ? "no result" : r[0].reason);
          if (csv) csv->close();
          return 2;
        }
      }
      const std::uint64_t received_before = plant.stats().commands_received;
      plant.publish_outputs(k);
      if (o.lockstep && !waiting) transport.spin_once(0);  // collect without waiting
      if (o.lockstep && !waiting && plant.stats().commands_received > received_before) {
        std::cerr << fmt::format("plant: commands are back at tick {}; lockstep resumes\n", k);
        waiting = true;
      }
      if (o.lockstep && waiting && k % divider == 0) {
        const bool status_expected = transport.matched_writers(topics.controller_status) > 0;
        auto answered = [&] {
          const bool command = plant.last_command_stamp_ns() == t_ns ||
                               (plant.last_command_stamp_ns() < 0 && plant.stats().commands_received > received_before);
          return stop_requested() || (command && (!status_expected || status.header.stamp.to_ns() == t_ns));
        };
        const std::int64_t asked = steady_ns();
        const std::int64_t deadline = asked + static_cast<std::int64_t>(o.timeout_s * 1e9);
        // Ask again every 50 ms: a sample sent while discovery was still settling may not arrive.
        while (!transport.spin_until(answered, 50 * kMs)) {
          if (steady_ns() >= deadline) {
            std::cerr << fmt::format(
                "plant: lockstep timeout: no motor command on {} for tick {} (t = {} s) after {} s; "
                "matched command writers: {}; policy: {}\n",
                topics.motor_commands, k, clock.seconds(k), o.timeout_s,
                transport.matched_writers(topics.motor_commands), o.on_timeout);
            if (o.on_timeout == "abort") {
              if (csv) csv->close();
              return 4;
            }
            waiting = false;  // hold the last command and go on
            break;
          }
          plant.publish_outputs(k);
        }
        round_trip_ns.push_back(steady_ns() - asked);
      } else if (!o.lockstep) {
        next_wall += period_wall;
        while (!stop_requested()) {
          const std::int64_t left = next_wall - steady_ns();
          if (left <= 0) break;
          transport.spin_once(left);
        }
      }
      plant.latch_command(k);
      record(k);
      if (mcap) mcap->flush_settled(t_ns);
      if (k < sc.simulation.duration_ticks) plant.integrate(k);
    }
    if (csv) csv->close();
    if (mcap) {
      while (transport.spin_once(0) > 0) {  // what is still in the readers
      }
      mcap->close();
      const std::filesystem::path p(o.mcap);
      mcap->write_bag_metadata(p.parent_path().empty() ? "." : p.parent_path().string(), p.filename().string());
    }
    const auto& st = plant.stats();
    const double wall_s = static_cast<double>(steady_ns() - loop_start) / 1e9;
    if (!round_trip_ns.empty()) {
      std::sort(round_trip_ns.begin(), round_trip_ns.end());
      auto pct = [&](double q) {
        return static_cast<double>(round_trip_ns[static_cast<std::size_t>(q * (round_trip_ns.size() - 1))]) / 1e3;
      };
      std::cerr << fmt::format("plant: lockstep round trip (outputs published -> command received) over {} "
                               "control periods: p50 {:.1f} us, p99 {:.1f} us, max {:.1f} us\n",
                               round_trip_ns.size(), pct(0.5), pct(0.99), pct(1.0));
    }
    const double sim_s = clock.seconds(sc.simulation.duration_ticks);
    std::cerr << fmt::format("plant: done; {:g} s simulated in {:.3f} s ({:.1f}x real time); commands received {}, "
                             "rejected {}, stale {}\n",
                             sim_s, wall_s, sim_s / wall_s, st.commands_received, st.commands_rejected,
                             st.commands_stale);
    return stop_requested() ? 130 : 0;
  } catch (const io::ConfigError& e) {
    std::cerr << "error: " << e.what() << '\n';
    return 2;
  } catch (const std::exception& e) {
    std::cerr << "error: plant: " << e.what() << '\n';
    return 3;
  }
}

int controller_command(const ControllerCommandOptions& o) {
  install_stop_handlers();
  try {
    io::Scenario sc = scenario_or_defaults(o.scenario, o.vehicle);
    if (!o.params.empty()) sc.controller = io::load_controller(o.params, sc.vehicle);
    if (!o.ns.empty()) sc.simulation.ns = o.ns;
    const sim::TickClock clock = sc.simulation.plant.clock;
    const std::int64_t control_period_ns = clock.period_ns * sc.simulation.controller_divider;
    const double dt_s = static_cast<double>(control_period_ns) / 1e9;
    const sim::Topics topics = sim::Topics::for_namespace(sc.simulation.ns);

    dds::DdsTransport transport(dds::read_ros_environment(o.enclave));
    if (o.sensor_qos) use_sensor_qos(transport, topics);
    sim::ControllerNode node(transport, topics, sc.controller);
    const dds::NodeName ros_name = dds::parse_node_name(o.node_name);
    // The ROS 2 parameter services, answered inside transport.spin_once (both loops below).
    dds::ParameterServer parameters(transport, ros_name, controller_parameter_callbacks(node));
    if (!o.apply_schedule) sc.schedule.clear();
    auto next_event = sc.schedule.begin();
    auto apply_schedule = [&](std::int64_t now_ns) {
      for (; next_event != sc.schedule.end() && clock.ns(next_event->tick) <= now_ns; ++next_event) {
        if (std::string err = node.set_parameter(next_event->name, next_event->value); !err.empty()) {
          throw std::invalid_argument("scheduled parameter refused: " + err);
        }
      }
    };
    dds::NodeAnnouncer announcer(transport.participant().handle(), ros_name.name, ros_name.ns);
    announcer.announce();  // after every endpoint exists: `ros2 node list` shows /attitude_controller
    std::cerr << fmt::format("controller: domain {}, namespace {}, {} mode, period {} s\n",
                             transport.participant().domain_id(), sc.simulation.ns,
                             o.lockstep ? "lockstep" : "real-time", dt_s);

    if (o.lockstep) {
      // Step once per complete sample of a control tick, on the sample's own time.
      while (!stop_requested()) {
        const int delivered = transport.spin_once(100 * kMs);
        const std::int64_t s = node.synchronized_stamp_ns();
        if (s < 0 || s % control_period_ns != 0) continue;
        if (s > node.last_step_ns()) {
          apply_schedule(s);
          node.step(s, dt_s);
        } else if (s == node.last_step_ns() && delivered > 0) {
          node.republish();  // the plant asked again for a tick we answered
        }
      }
    } else {
      // Real time: a 50 Hz (or configured) timer; data age is measured on the receiving clock.
      node.use_receipt_clock(steady_ns);
      const auto wall_period_ns =
          static_cast<std::int64_t>(static_cast<double>(control_period_ns) / o.rate_factor);
      std::int64_t next = steady_ns();
      while (!stop_requested()) {
        next += wall_period_ns;
        for (std::int64_t left; !stop_requested() && (left = next - steady_ns()) > 0;) transport.spin_once(left);
        const std::int64_t sim_now = node.newest_stamp_ns();
        apply_schedule(sim_now < 0 ? 0 : sim_now);
        node.step(steady_ns(), dt_s);
      }
    }
    std::cerr << "controller: stopped\n";
    return 0;
  } catch (const io::ConfigError& e) {
    std::cerr << "error: " << e.what() << '\n';
    return 2;
  } catch (const control::CareError& e) {
    std::cerr << "error: controller design failed: " << e.what() << '\n';
    return 2;
  } catch (const std::exception& e) {
    std::cerr << "error: controller: " << e.what() << '\n';
    return 3;
  }
}

}  // namespace quadcosim::app
