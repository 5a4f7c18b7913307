// `quadcosim controller`: its flags, and the scenario as they change it (a parameter file, an FMU, a
// Python controller); the controller process itself is hosts/controller_process.hpp (one vehicle) and
// hosts/swarm_nodes.hpp (--vehicles N).
#include <fmt/format.h>
#include <CLI/CLI.hpp>

#include <filesystem>
#include <iostream>

#include "app/commands.hpp"
#include "app/exit_codes.hpp"
#include "app/foxglove_cli.hpp"
#include "hosts/controller_process.hpp"
#include "hosts/swarm_nodes.hpp"
#include "io/scenario.hpp"
#include "python/embedded/python_host.hpp"

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

int controller_command(const ControllerCommandOptions& o, const io::ScenarioResolvers& resolvers) {
  std::optional<io::Scenario> started =
      hosts::start_node_process("controller", o.cpus, o.scenario, o.vehicle, o.ns, resolvers, o.controller);
  if (!started) return exit_code::kBadInput;
  io::Scenario& sc = *started;
  if (!o.params.empty()) {
    // The file replaces the controller and the node's parameters; the scenario's trajectory stays.
    const auto trajectory = sc.controller.trajectory;
    sc.controller = io::load_controller(o.params, sc.vehicle, resolvers);
    sc.controller.trajectory = trajectory;
  }
  if (!o.fmu.empty()) io::use_controller_fmu(sc, io::FmuSpec{o.fmu, {}}, "--fmu", resolvers);
  if (!o.python.empty()) {
    // Replaces the controller only: the node's setpoints, safety and trajectory stay the scenario's.
    const std::filesystem::path folder =
        o.scenario.empty() ? std::filesystem::path() : std::filesystem::path(o.scenario).parent_path();
    sc.controller.controller =
        embedded_python::make_python_controller(o.python, folder, sc.controller.vehicle, "--python");
    sc.controller_fmu.reset();
  }
  if (o.swarm.vehicles > 0) {
    // The swarm's shards step their vehicles' controllers in turn on shared threads: a controller that
    // asks for a thread of its own (Controller::wants_own_thread: one written in Python, a SITL
    // firmware) cannot be one of them.
    if (sc.controller.wants_own_thread()) {
      throw io::ConfigError(
          fmt::format("controller: a {} controller runs on a thread of its own and flies one vehicle (no --vehicles)",
                      sc.controller.type()));
    }
    return hosts::run_controller_swarm(o, std::move(sc));
  }
  return hosts::run_controller_process(o, std::move(sc), embedded_python::python_thread_host());
}

}  // namespace quadcosim::app
