// `quadcosim controller`: the flight controller node as a long-running process over DDS, stepping
// once per complete sensor sample in lockstep, or on a wall-clock timer in real time.
#include <fmt/format.h>

#include <iostream>

#include "app/commands.hpp"
#include "app/node_common.hpp"
#include "app/parameter_binding.hpp"
#include "app/signals.hpp"
#include "app/swarm.hpp"
#include "control/care.hpp"
#include "dds/dds_transport.hpp"
#include "dds/node_announcer.hpp"
#include "dds/parameter_service.hpp"
#include "io/scenario.hpp"
#include "drivers/controller_drivers.hpp"
#include "sim/controller_node.hpp"

namespace quadcosim::app {

int controller_command(const ControllerCommandOptions& o) {
  install_stop_handlers();
  // Before any DDS participant: Cyclone's threads inherit the affinity.
  if (std::string err = use_cpus(o.cpus); !err.empty()) {
    std::cerr << "error: controller: --cpus: " << err << '\n';
    return 2;
  }
  // One write: run --pin starts both processes on one stderr, and grep reads whole lines.
  if (!o.cpus.empty()) std::cerr << fmt::format("controller: on CPU(s) {} only\n", o.cpus);
  try {
    io::Scenario sc = scenario_or_defaults(o.scenario, o.vehicle);
    if (!o.params.empty()) sc.controller = io::load_controller(o.params, sc.vehicle);
    if (!o.ns.empty()) sc.simulation.ns = o.ns;
    refuse_faults_over_dds(sc);
    if (o.vehicles > 0) return swarm_controller_command(o, std::move(sc));
    const sim::TickClock clock = sc.simulation.plant.clock;
    const std::int64_t control_period_ns = clock.period_ns * sc.simulation.controller_divider;
    const double dt_s = static_cast<double>(control_period_ns) / 1e9;
    const sim::Topics topics = sim::Topics::for_namespace(sc.simulation.ns);

    dds::DdsTransport transport(dds::read_ros_environment(o.enclave));
    if (o.sensor_qos) use_sensor_qos(transport, topics);
    sim::ControllerNode node(transport, topics, sc.controller);
    const dds::NodeName ros_name = dds::parse_node_name(o.node_name);
    // The ROS 2 parameter services, answered in the transport's waits (both drivers below).
    dds::ParameterServer parameters(transport, ros_name, controller_parameter_callbacks(node));
    if (!o.apply_schedule) sc.schedule.clear();
    dds::NodeAnnouncer announcer(transport.participant().handle(), ros_name.name, ros_name.ns);
    announcer.announce();  // after every endpoint exists: `ros2 node list` shows /attitude_controller
    std::cerr << fmt::format("controller: domain {}, namespace {}, {} mode, period {} s\n",
                             transport.participant().domain_id(), sc.simulation.ns,
                             o.lockstep ? "lockstep" : "real-time", dt_s);

    if (o.lockstep) {
      // Steps where the samples are delivered: on Cyclone's receive thread with delivery on
      // arrival, so answering a tick wakes no other thread; the host's waits serve the parameter
      // services.
      DdsDriverHost host(transport);
      drivers::LockstepControllerDriver driver({{&node, std::move(sc.schedule)}}, clock,
                                               sc.simulation.controller_divider, host);
      driver.run();
    } else {
      // Real time: a 50 Hz (or configured) timer; data age is measured on the receiving clock.
      node.use_receipt_clock(steady_ns);
      if (std::string err = use_realtime_priority(o.rt_priority); !err.empty()) {
        std::cerr << "controller: warning: " << err << "; running with normal scheduling\n";
      }
      const auto wall_period_ns =
          static_cast<std::int64_t>(static_cast<double>(control_period_ns) / o.rate_factor);
      PeriodJitter jitter(wall_period_ns);
      drivers::RealtimeControllerHooks h;
      h.on_wake = [&](std::int64_t now) { jitter.add(now); };
      h.on_first_sample = [](std::size_t, std::int64_t stamp_ns) {
        std::cerr << fmt::format("controller: first complete sensor sample (t = {:g} s); controlling\n",
                                 static_cast<double>(stamp_ns) / 1e9);
      };
      h.on_safety = [&](std::size_t, bool safety, std::int64_t now) {
        std::cerr << fmt::format("controller: {} (sensor data age {:.3f} s, limit {:g} s; monotonic {:.6f} s)\n",
                                 safety ? "stale sensor data: safety command" : "sensor data fresh again: normal control",
                                 node.estimate().age_s, node.config().params.stale_limit_s,
                                 static_cast<double>(now) / 1e9);
      };
      DdsDriverHost host(transport, /*precise_deadlines=*/true);
      drivers::RealtimeControllerDriver driver({{&node, std::move(sc.schedule)}}, clock,
                                               sc.simulation.controller_divider, o.rate_factor, std::move(h), host);
      driver.run();
      if (!o.stats.empty()) write_stats(o.stats, jitter.figures());
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
