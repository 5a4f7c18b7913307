// `quadcosim plant`: its flags, and the scenario as they change it; the plant process itself is
// hosts/plant_process.hpp (one vehicle) and hosts/swarm_nodes.hpp (--vehicles N).
#include <fmt/format.h>
#include <CLI/CLI.hpp>

#include <cmath>
#include <iostream>
#include <optional>
#include <utility>

#include "app/commands.hpp"
#include "app/exit_codes.hpp"
#include "app/foxglove_cli.hpp"
#include "hosts/node_common.hpp"
#include "hosts/plant_process.hpp"
#include "hosts/swarm_nodes.hpp"
#include "io/scenario.hpp"

namespace quadcosim::app {

CLI::App* add_plant_subcommand(CLI::App& app, PlantCommandOptions& plant) {
  auto* plant_cmd = app.add_subcommand("plant", "the plant as a ROS 2 node over DDS (until done or Ctrl-C)");
  plant_cmd->add_option("--scenario", plant.scenario, "scenario YAML (vehicle, rates, duration, initial state)")
      ->check(CLI::ExistingFile);
  plant_cmd->add_option("--vehicle", plant.vehicle, "vehicle YAML (replaces the scenario's vehicle)")
      ->check(CLI::ExistingFile);
  plant_cmd
      ->add_option("--fmu", plant.fmu,
                   "fly this co-simulation FMU as the plant, its variables by their default names "
                   "(replaces the scenario's plant; docs/fmi.md)")
      ->check(CLI::ExistingPath);
  add_node_host_options(plant_cmd, plant.ns, plant.swarm, plant.sensor_qos,
                        "publish Pose/Velocity/Imu best effort (ROS sensor data QoS)", plant.cpus);
  plant_cmd->add_flag("!--realtime", plant.lockstep, "pace by the wall clock instead of lockstep (one vehicle)");
  plant_cmd->add_option("--rate-factor", plant.realtime.rate_factor, "real time: run k times faster")
      ->check(CLI::Range(1e-3, 1e6));
  plant_cmd->add_option("--duration", plant.duration_s, "simulated time [s]")->check(CLI::Range(0.0, 1e9));
  plant_cmd->add_option("--record", plant.one_vehicle.record, "one vehicle: write the trajectory CSV here");
  plant_cmd->add_option("--mcap", plant.one_vehicle.mcap,
                        "one vehicle: record the topics as MCAP here (metadata.yaml beside it)");
  plant_cmd
      ->add_option("--timeout", plant.timeout_s,
                   "lockstep: wait for the controller / a command; real time: for the controller "
                   "(--wait-for-controller) and each --schedule-via answer [s]")
      ->check(CLI::Range(0.01, 3600.0));
  plant_cmd
      ->add_option("--schedule-via", plant.one_vehicle.schedule_node,
                   "one vehicle: apply the scenario's schedule through this node's parameter services")
      ->check(CLI::Validator(check_node_name, "NODE"));
  plant_cmd->add_flag("--wait-for-controller", plant.realtime.wait_for_controller,
                      "real time: start only once a controller is matched (up to --timeout)");
  plant_cmd->add_option("--stats", plant.stats, "write the run's figures (real-time factor, round trip) as JSON here");
  plant_cmd->add_option("--swarm-out", plant.swarm.out, "with --vehicles: write summary.json, vehicles.csv here");
  plant_cmd
      ->add_option("--on-timeout", plant.lockstep_only.on_timeout, "lockstep: abort (exit 4) or hold the last command")
      ->check(CLI::IsMember({"abort", "hold"}));
  plant_cmd
      ->add_option("--watchdog", plant.watchdog_s,
                   "no valid motor command for this long [s] -> the watchdog policy (0: off; "
                   "default: the scenario's simulation.watchdog_s, 0.5)")
      ->check(CLI::Range(0.0, 1e6));
  plant_cmd
      ->add_option("--watchdog-policy", plant.watchdog_policy,
                   "hold: keep the last command; stop: motors to omega_min (default: the scenario's, stop)")
      ->check(CLI::IsMember({"hold", "stop"}));

  plant_cmd
      ->add_option("--sync", plant.lockstep_only.sync,
                   "lockstep, one vehicle: how the controller steps: samples (on each control tick's samples, "
                   "as quadcosim's controller), clock (from a timer on ROS time, as rclcpp and rclpy nodes with "
                   "use_sim_time: each tick's samples then a get_parameters request to its node, a control tick's "
                   "/clock after the reply), auto (clock when "
                   "the node publishing the commands has use_sim_time true; docs/ros2.md)")
      ->check(CLI::IsMember({"auto", "samples", "clock"}));
  plant_cmd
      ->add_option("--controller-node", plant.lockstep_only.controller_node,
                   "the controller's node: only the writers of its process are the controller's, and --sync "
                   "clock/auto asks it (default: the one process publishing the motor commands, and its node with "
                   "parameter services)")
      ->check(CLI::Validator(check_node_name, "NODE"));
  plant_cmd->add_flag("--clock-after-sensors", plant.clock_after_sensors,
                      "publish /clock after each tick's Pose, Velocity and Imu (for a peer that steps on "
                      "/clock and reads the newest samples: Simulink's ROS 2 time model; docs/simulink.md)");

  add_foxglove_options(*plant_cmd, plant.foxglove, /*inprocess=*/false);
  add_enclave_option(plant_cmd, plant.enclave);
  // Flags that do nothing in the chosen mode are refused (exit 2), naming the flag and the mode.
  plant_cmd->parse_complete_callback([plant_cmd, &plant] {
    const bool swarm = plant.swarm.vehicles > 0, realtime = !plant.lockstep;
    refuse_idle_flags(
        *plant_cmd,
        {
            {"--realtime", !swarm, "--vehicles; a swarm runs in lockstep only"},
            {"--namespace", !swarm, "--vehicles; each vehicle's namespace is <--ns-prefix>0000, ..."},
            {"--record", !swarm, "--vehicles; a swarm records with --swarm-out"},
            {"--mcap", !swarm, "--vehicles; a swarm records with --swarm-out"},
            {"--foxglove", !swarm, "--vehicles; one vehicle is served"},
            {"--schedule-via", !swarm, "--vehicles; each vehicle's controller applies the schedule"},
            {"--ns-prefix", swarm, "one vehicle; it needs --vehicles N"},
            {"--threads", swarm, "one vehicle; it needs --vehicles N"},
            {"--swarm-out", swarm, "one vehicle; it needs --vehicles N"},
            {"--rate-factor", realtime, "lockstep; it needs --realtime"},
            {"--wait-for-controller", realtime, "lockstep; it needs --realtime (lockstep always waits)"},
            {"--on-timeout", !realtime, "--realtime; it is the lockstep timeout's policy"},
            {"--sync", !realtime && !swarm, "--realtime or --vehicles; it is one vehicle's lockstep protocol"},
            {"--controller-node", !swarm && (!realtime || plant.realtime.wait_for_controller),
             "--vehicles, or --realtime without --wait-for-controller"},
            {"--timeout", !realtime || plant.realtime.wait_for_controller || !plant.one_vehicle.schedule_node.empty(),
             "--realtime alone; it needs lockstep, --wait-for-controller or --schedule-via"},
        });
  });
  return plant_cmd;
}

int plant_command(const PlantCommandOptions& o, const io::ScenarioResolvers& resolvers) {
  std::optional<io::Scenario> started =
      hosts::start_node_process("plant", o.cpus, o.scenario, o.vehicle, o.ns, resolvers);
  if (!started) return exit_code::kBadInput;
  io::Scenario& sc = *started;
  if (!o.fmu.empty()) io::use_plant_fmu(sc, io::FmuSpec{o.fmu, {}}, "--fmu", resolvers);
  if (o.watchdog_s >= 0.0) {
    const double ticks = o.watchdog_s / sc.simulation.plant.clock.period_s();
    if (std::abs(ticks - std::round(ticks)) > 1e-6) {
      std::cerr << fmt::format("error: --watchdog {:g}: expected a whole number of plant periods ({:g} s)\n",
                               o.watchdog_s, sc.simulation.plant.clock.period_s());
      return exit_code::kBadInput;
    }
    sc.simulation.plant.watchdog_ticks = static_cast<sim::Tick>(std::round(ticks));
  }
  if (!o.watchdog_policy.empty()) {
    sc.simulation.plant.watchdog_policy =
        o.watchdog_policy == "hold" ? sim::WatchdogPolicy::kHold : sim::WatchdogPolicy::kStop;
  }
  sc.simulation.plant.clock_after_sensors = o.clock_after_sensors;
  if (o.duration_s >= 0.0) {
    sc.simulation.duration_ticks = static_cast<sim::Tick>(o.duration_s / sc.simulation.plant.clock.period_s() + 0.5);
  }
  if (o.swarm.vehicles > 0) return hosts::run_plant_swarm(o, std::move(sc));
  return hosts::run_plant_process(o, std::move(sc));
}

}  // namespace quadcosim::app
