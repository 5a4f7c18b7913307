// `quadcosim controller`: the flight controller node as a long-running process over DDS, stepping
// once per complete sensor sample in lockstep, or on a wall-clock timer in real time.
#include <fmt/format.h>
#include <CLI/CLI.hpp>

#include <filesystem>
#include <iostream>

#include "app/commands.hpp"
#include "app/exit_codes.hpp"
#include "app/foxglove_cli.hpp"
#include "app/python_host.hpp"
#include "app/swarm.hpp"
#include "dds/dds_transport.hpp"
#include "dds/node_announcer.hpp"
#include "dds/parameter_service.hpp"
#include "dds/peer_pairing.hpp"
#include "drivers/controller_drivers.hpp"
#include "hosts/node_common.hpp"
#include "hosts/parameter_binding.hpp"
#include "hosts/signals.hpp"
#include "io/scenario.hpp"
#include "isolation/child.hpp"
#include "sim/controller_node.hpp"
#include "sim/topics.hpp"

namespace quadcosim::app {

CLI::App* add_controller_subcommand(CLI::App& app, ControllerCommandOptions& ctl) {
  auto* ctl_cmd = app.add_subcommand("controller", "the flight controller as a ROS 2 node over DDS");
  ctl_cmd->add_option("--scenario", ctl.scenario, "scenario YAML (controller parameters, rates, schedule)")
      ->check(CLI::ExistingFile);
  add_controller_type_option(*ctl_cmd, ctl.controller);
  ctl_cmd
      ->add_option("--params", ctl.params,
                   "controller parameter YAML (its keys on top of the controller type's "
                   "and the node's defaults; `type:` included)")
      ->check(CLI::ExistingFile);
  ctl_cmd->add_option("--vehicle", ctl.vehicle, "vehicle YAML (the controller's model of the vehicle)")
      ->check(CLI::ExistingFile);
  ctl_cmd
      ->add_option("--fmu", ctl.fmu,
                   "fly this co-simulation FMU as the controller, its variables by their default names "
                   "(replaces the scenario's controller, keeps its setpoints; docs/fmi.md)")
      ->check(CLI::ExistingPath)
      ->excludes("--controller")
      ->excludes("--params");
  ctl_cmd
      ->add_option("--python", ctl.python,
                   "fly a controller written in Python, MODULE:CLASS (the module found in the scenario's folder, "
                   "the current directory or PYTHONPATH; replaces the scenario's controller, keeps its setpoints; "
                   "docs/python.md)")
      ->excludes("--controller")
      ->excludes("--params")
      ->excludes("--fmu");
  ctl_cmd
      ->add_option("--on-controller-error", ctl.on_controller_error,
                   "a Python controller's step that raises or returns garbage: stop the node (exit 5), or send the "
                   "stale-data safety command for that step and keep flying (counted, logged)")
      ->check(CLI::IsMember({"stop", "safety"}));
  add_node_host_options(ctl_cmd, ctl.ns, ctl.swarm, ctl.sensor_qos,
                        "subscribe Pose/Velocity/Imu best effort (ROS sensor data QoS)", ctl.cpus);
  ctl_cmd->add_flag("!--realtime", ctl.lockstep, "step on a wall-clock timer instead of lockstep (one vehicle)");
  ctl_cmd->add_flag("!--no-schedule", ctl.apply_schedule,
                    "ignore the scenario's schedule (someone else sets the parameters)");
  ctl_cmd->add_option("--rate-factor", ctl.realtime.rate_factor, "real time: run the timer k times faster")
      ->check(CLI::Range(1e-3, 1e6));
  ctl_cmd
      ->add_option("--rt-priority", ctl.realtime.rt_priority,
                   "real time: run the control loop under SCHED_FIFO at this priority (needs CAP_SYS_NICE)")
      ->check(CLI::Range(0, 99));
  ctl_cmd->add_option("--stats", ctl.realtime.stats, "real time: write the control period jitter as JSON here on exit");
  ctl_cmd
      ->add_option("--node-name", ctl.one_vehicle.node_name,
                   "one vehicle: ROS node name (parameter services /NAME/..., ros2 node list)")
      ->check(CLI::Validator(check_node_name, "NAME"));

  add_foxglove_options(*ctl_cmd, ctl.foxglove, /*inprocess=*/false);
  add_enclave_option(ctl_cmd, ctl.enclave);
  // Flags that do nothing in the chosen mode are refused (exit 2), naming the flag and the mode.
  ctl_cmd->parse_complete_callback([ctl_cmd, &ctl] {
    const bool swarm = ctl.swarm.vehicles > 0, realtime = !ctl.lockstep;
    refuse_idle_flags(
        *ctl_cmd,
        {
            {"--realtime", !swarm, "--vehicles; a swarm runs in lockstep only"},
            {"--namespace", !swarm, "--vehicles; each vehicle's namespace is <--ns-prefix>0000, ..."},
            {"--node-name", !swarm, "--vehicles; a swarm offers no parameter services"},
            {"--python", !swarm, "--vehicles; a Python controller flies one vehicle"},
            {"--foxglove", !swarm, "--vehicles; one vehicle is served"},
            {"--ns-prefix", swarm, "one vehicle; it needs --vehicles N"},
            {"--threads", swarm, "one vehicle; it needs --vehicles N"},
            {"--rate-factor", realtime, "lockstep; it needs --realtime"},
            {"--rt-priority", realtime, "lockstep; it needs --realtime"},
            {"--stats", realtime, "lockstep; it needs --realtime (in lockstep the plant's --stats has the figures)"},
        });
  });
  return ctl_cmd;
}

namespace {
/// Runs a node's loop. A step given up on SIGINT or SIGTERM (an isolated Python controller's process
/// is killed on a stop request, and the steps after find it gone) ends the node as the signal does,
/// exit 0, not as a failure of the controller.
template <class Loop>
void run_until_stopped(Loop&& loop) {
  try {
    loop();
  } catch (const sim::ControllerFailure& e) {
    if (!hosts::stop_signalled()) throw;
    std::cerr << "controller: stop requested while the controller was stepping (" << e.what() << ")\n";
  } catch (const isolation::Interrupted& e) {
    if (!hosts::stop_signalled()) throw;
    std::cerr << "controller: " << e.what() << '\n';
  }
}
}  // namespace

int controller_command(const ControllerCommandOptions& o) {
  std::optional<io::Scenario> started =
      hosts::start_node_process("controller", o.cpus, o.scenario, o.vehicle, o.ns, o.controller);
  if (!started) return exit_code::kBadInput;
  io::Scenario& sc = *started;
  if (!o.params.empty()) {
    // The file replaces the controller and the node's parameters; the scenario's trajectory stays.
    const auto trajectory = sc.controller.trajectory;
    sc.controller = io::load_controller(o.params, sc.vehicle);
    sc.controller.trajectory = trajectory;
  }
  if (!o.fmu.empty()) io::use_controller_fmu(sc, io::FmuSpec{o.fmu, {}}, "--fmu");
  if (!o.python.empty()) {
    // Replaces the controller only: the node's setpoints, safety and trajectory stay the scenario's.
    const std::filesystem::path folder =
        o.scenario.empty() ? std::filesystem::path() : std::filesystem::path(o.scenario).parent_path();
    sc.controller.controller = make_python_controller(o.python, folder, sc.controller.vehicle, "--python");
    sc.controller_fmu.reset();
  }
  if (o.swarm.vehicles > 0) {
    if (sc.controller.type() == "python") {
      throw io::ConfigError("controller: a Python controller flies one vehicle (no --vehicles)");
    }
    return swarm_controller_command(o, std::move(sc));
  }
  const sim::TickClock clock = sc.simulation.plant.clock;
  const std::int64_t control_period_ns = clock.period_ns * sc.simulation.controller_divider;
  const double dt_s = static_cast<double>(control_period_ns) / 1e9;
  const auto wall_period_ns =
      static_cast<std::int64_t>(static_cast<double>(control_period_ns) / o.realtime.rate_factor);
  const sim::Topics topics = sim::Topics::for_namespace(sc.simulation.ns);

  dds::DdsTransport transport(dds::read_ros_environment(o.enclave));
  if (o.sensor_qos) hosts::use_sensor_qos(transport, topics);
  // Paired with the plant by the run's token (run --transport dds): the node's writers carry it, and
  // it takes sensor samples from the plant's writers only (dds/peer_pairing.hpp).
  const std::string pair_token = dds::pair_token_from_environment();
  dds::PeerFilter pairing(transport);
  sim::ControllerNode::SampleFilter from_plant;
  if (!pair_token.empty()) {
    transport.set_user_data_keys(std::string(dds::kPairTokenKey) + "=" + pair_token + ";");
    pairing.pair_by_token(pair_token);
    from_plant = [&pairing](const std::string& topic, sim::SenderId s) { return pairing.accepts(topic, s); };
  }
  sim::ControllerNode node(transport, topics, sc.controller, std::move(from_plant),
                           sc.simulation.plant.realism.extra_sensors);
  // A controller that asks for it (one written in Python, docs/python.md) runs on a thread of its own:
  // one that blocks holds up neither the DDS threads (discovery, parameter services) nor a stop.
  const bool on_thread = sc.controller.wants_own_thread();
  if (on_thread) {
    sim::ControllerThreading threading;
    threading.asynchronous = o.lockstep;
    threading.wait_ns = wall_period_ns * 3 / 4;
    threading.on_error = o.on_controller_error == "safety" ? sim::ControllerThreading::OnError::kSafety
                                                           : sim::ControllerThreading::OnError::kStop;
    threading.on_failure = [](const std::string&) { hosts::request_stop(); };
    threading.thread_host = python_thread_host();
    node.run_controller_on_thread(std::move(threading));
  }
  const dds::NodeName ros_name = dds::parse_node_name(o.one_vehicle.node_name);
  // The ROS 2 parameter services, answered in the transport's waits (both drivers below).
  dds::ParameterServer parameters(transport, ros_name, hosts::controller_parameter_callbacks(node));
  if (!o.apply_schedule) sc.schedule.clear();
  // After the node's own readers, so a plant that counts this process's readers finds the node's first.
  std::unique_ptr<foxglove::Server> fox = hosts::start_foxglove(o.foxglove, "controller", transport, topics, sc);
  dds::NodeAnnouncer announcer(transport.participant().handle(), ros_name.name, ros_name.ns);
  announcer.announce();  // after every endpoint exists: `ros2 node list` shows /attitude_controller
  std::cerr << fmt::format("controller: domain {}, namespace {}, {} mode, period {} s, controller {}\n",
                           transport.participant().domain_id(), sc.simulation.ns, o.lockstep ? "lockstep" : "real-time",
                           dt_s,
                           sc.controller_fmu   ? "fmu " + sc.controller_fmu->path
                           : !o.python.empty() ? "python " + o.python
                                               : std::string(sc.controller.type()));

  if (o.lockstep) {
    // Steps where the samples are delivered: on Cyclone's receive thread with delivery on
    // arrival, so answering a tick wakes no other thread; the host's waits serve the parameter
    // services.
    hosts::DdsDriverHost host(transport);
    drivers::LockstepControllerDriver driver({{&node, std::move(sc.schedule)}}, clock, sc.simulation.controller_divider,
                                             host);
    run_until_stopped([&] { driver.run(); });
  } else {
    // Real time: a 50 Hz (or configured) timer; data age is measured on the receiving clock.
    node.use_receipt_clock(hosts::steady_ns);
    if (std::string err = hosts::use_realtime_priority(o.realtime.rt_priority); !err.empty()) {
      std::cerr << "controller: warning: " << err << "; running with normal scheduling\n";
    }
    hosts::PeriodJitter jitter(wall_period_ns);
    drivers::RealtimeControllerHooks h;
    h.on_wake = [&](std::int64_t now) { jitter.add(now); };
    h.on_first_sample = [](std::size_t, std::int64_t stamp_ns) {
      std::cerr << fmt::format("controller: first complete sensor sample (t = {:g} s); controlling\n",
                               static_cast<double>(stamp_ns) / 1e9);
    };
    h.on_safety = [&](std::size_t, bool safety, std::int64_t now) {
      // On a thread, the safety command also stands in for a late or failed step (counted and logged).
      const bool stale = node.observation().age_s > node.settings().stale_limit_s;
      std::cerr << fmt::format("controller: {} (sensor data age {:.3f} s, limit {:g} s; monotonic {:.6f} s)\n",
                               safety                ? (stale || !on_thread ? "stale sensor data: safety command"
                                                                            : "no answer from the controller: safety command")
                               : stale || !on_thread ? "sensor data fresh again: normal control"
                                                     : "the controller answers again: normal control",
                               node.observation().age_s, node.settings().stale_limit_s, static_cast<double>(now) / 1e9);
    };
    hosts::DdsDriverHost host(transport, /*precise_deadlines=*/true);
    drivers::RealtimeControllerDriver driver({{&node, std::move(sc.schedule)}}, clock, sc.simulation.controller_divider,
                                             o.realtime.rate_factor, std::move(h), host);
    run_until_stopped([&] { driver.run(); });
    if (!o.realtime.stats.empty()) hosts::write_stats(o.realtime.stats, jitter.figures());
  }
  if (std::optional<std::string> failure = node.controller_failure(); failure && !hosts::stop_signalled()) {
    throw sim::ControllerFailure(*failure);
  }
  if (on_thread && (node.controller_failures() > 0 || node.late_steps() > 0)) {
    std::cerr << fmt::format(
        "controller: {} failed steps (safety command sent instead), {} {}\n", node.controller_failures(),
        node.late_steps(), o.lockstep ? "ticks not answered (controller busy)" : "late periods (safety command sent)");
  }
  if (node.foreign_samples() > 0) {
    std::cerr << fmt::format("controller: {} sensor samples from writers other than the plant's ignored\n",
                             node.foreign_samples());
  }
  std::cerr << "controller: stopped\n";
  if (fox) hosts::finish_foxglove(o.foxglove, "controller", *fox);
  return exit_code::kOk;
}

}  // namespace quadcosim::app
