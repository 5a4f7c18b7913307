// quadcosim: one binary, one subcommand per job.
#include <CLI/CLI.hpp>

#include <iostream>
#include <string>

#include "app/commands.hpp"
#include "sim/topics.hpp"

namespace {

// The first argument when it is neither a subcommand of `app` nor a flag `app` knows: CLI11 would
// only say "A subcommand is required" without naming it.
std::string unknown_first_argument(const CLI::App& app, int argc, char** argv) {
  if (argc < 2) return {};
  const std::string first = argv[1];
  if (first == "-h" || first == "--help" || first == "--version") return {};
  for (const CLI::App* sub : app.get_subcommands({})) {
    if (sub->get_name() == first) return {};
  }
  return first;
}

}  // namespace

int main(int argc, char** argv) {
  using namespace quadcosim::app;
  CLI::App app{"quadcosim: quadrotor flight-controller co-simulation (plant + ROS 2-style controller)"};
  app.require_subcommand(1);
  app.set_version_flag("--version", std::string("quadcosim ") + QUADCOSIM_VERSION);

  RunOptions run;
  auto* run_cmd = app.add_subcommand("run", "run a scenario: trajectory.csv, metrics.json, plots");
  run_cmd->add_option("scenario", run.scenario, "scenario YAML file")->required()->check(CLI::ExistingFile);
  run_cmd->add_option("--out", run.out_dir, "output directory (created)")->required();
  run_cmd->add_flag("!--no-plots", run.plots, "skip the PNG plots and report.html");
  run_cmd->add_option("--transport", run.transport,
                      "inproc: one process; dds: plant and controller as two processes over DDS, lockstep")
      ->check(CLI::IsMember({"inproc", "dds"}));
  run_cmd->add_option("--timeout", run.timeout_s, "dds: lockstep wait for a command [s]")
      ->check(CLI::Range(0.01, 3600.0));
  run_cmd->add_option("--keystore", run.keystore,
                      "dds: run secured (SROS2 keystore, Enforce); created when missing, with enclaves "
                      "/quadcosim/plant and /quadcosim/controller");
  run_cmd->add_flag("--pin", run.pin,
                    "dds: plant on one CPU, controller on another (the first two this process may use)");
  run_cmd->add_flag("--realtime", run.realtime, "dds: pace by the wall clock, as in the paper, not lockstep");
  run_cmd->add_option("--rate-factor", run.rate_factor, "dds real time: run k times faster")
      ->check(CLI::Range(1e-3, 1e6));
  run_cmd->add_option("--vehicles", run.vehicles, "a swarm of N vehicles on a grid (default: the scenario's swarm section)")
      ->check(CLI::Range(1, 10'000'000));
  run_cmd->add_option("--threads", run.threads, "in-process swarm: worker threads (default: swarm.threads, 2)")
      ->check(CLI::Range(1, 64));

  PlantCommandOptions plant;
  auto* plant_cmd = app.add_subcommand("plant", "the plant as a ROS 2 node over DDS (until done or Ctrl-C)");
  plant_cmd->add_option("--scenario", plant.scenario, "scenario YAML (vehicle, rates, duration, initial state)")
      ->check(CLI::ExistingFile);
  plant_cmd->add_option("--vehicle", plant.vehicle, "vehicle YAML (replaces the scenario's vehicle)")
      ->check(CLI::ExistingFile);
  const CLI::Validator ros_namespace(quadcosim::sim::validate_namespace, "NAMESPACE");
  plant_cmd->add_option("--namespace", plant.ns, "topic namespace, e.g. /uav1")->check(ros_namespace);
  plant_cmd->add_option("--vehicles", plant.vehicles, "host N vehicles, namespaces <prefix>0000.. (lockstep)")
      ->check(CLI::Range(1, 1'000'000));
  plant_cmd->add_option("--ns-prefix", plant.ns_prefix, "with --vehicles: namespace prefix (default: swarm.namespace_prefix, /uav)");
  plant_cmd->add_option("--threads", plant.threads, "with --vehicles: threads, one DDS participant each")
      ->check(CLI::Range(1, 64));
  plant_cmd->add_flag("--sensor-qos", plant.sensor_qos, "publish Pose/Velocity/Imu best effort (ROS sensor data QoS)");
  add_cpus_option(plant_cmd, plant.cpus);
  plant_cmd->add_flag("!--realtime", plant.lockstep, "pace by the wall clock instead of lockstep");
  plant_cmd->add_option("--rate-factor", plant.rate_factor, "real time: run k times faster")
      ->check(CLI::Range(1e-3, 1e6));
  plant_cmd->add_option("--duration", plant.duration_s, "simulated time [s]")->check(CLI::Range(0.0, 1e9));
  plant_cmd->add_option("--record", plant.record, "write the trajectory CSV here");
  plant_cmd->add_option("--mcap", plant.mcap, "record the topics as MCAP here (metadata.yaml beside it)");
  plant_cmd->add_option("--timeout", plant.timeout_s, "lockstep: wait for the controller / a command [s]")
      ->check(CLI::Range(0.01, 3600.0));
  plant_cmd->add_option("--schedule-via", plant.schedule_node,
                        "lockstep: apply the scenario's schedule through this node's parameter services");
  plant_cmd->add_flag("--wait-for-controller", plant.wait_for_controller,
                      "real time: start only once a controller is matched (up to --timeout)");
  plant_cmd->add_option("--stats", plant.stats, "write the run's figures (real-time factor, round trip) as JSON here");
  plant_cmd->add_option("--swarm-out", plant.swarm_out, "with --vehicles: write summary.json, vehicles.csv here");
  plant_cmd->add_option("--on-timeout", plant.on_timeout, "lockstep: abort (exit 4) or hold the last command")
      ->check(CLI::IsMember({"abort", "hold"}));
  plant_cmd->add_option("--watchdog", plant.watchdog_s,
                        "no valid motor command for this long [s] -> the watchdog policy (0: off; "
                        "default: the scenario's simulation.watchdog_s, 0.5)")
      ->check(CLI::Range(0.0, 1e6));
  plant_cmd->add_option("--watchdog-policy", plant.watchdog_policy,
                        "hold: keep the last command; stop: motors to omega_min (default: the scenario's, stop)")
      ->check(CLI::IsMember({"hold", "stop"}));

  add_enclave_option(plant_cmd, plant.enclave);

  ControllerCommandOptions ctl;
  auto* ctl_cmd = app.add_subcommand("controller", "the flight controller as a ROS 2 node over DDS");
  ctl_cmd->add_option("--scenario", ctl.scenario, "scenario YAML (controller parameters, rates, schedule)")
      ->check(CLI::ExistingFile);
  ctl_cmd->add_option("--params", ctl.params, "controller parameter YAML")->check(CLI::ExistingFile);
  ctl_cmd->add_option("--vehicle", ctl.vehicle, "vehicle YAML (the controller's model of the vehicle)")
      ->check(CLI::ExistingFile);
  ctl_cmd->add_option("--namespace", ctl.ns, "topic namespace, e.g. /uav1")->check(ros_namespace);
  ctl_cmd->add_option("--vehicles", ctl.vehicles, "host N vehicles, namespaces <prefix>0000.. (lockstep)")
      ->check(CLI::Range(1, 1'000'000));
  ctl_cmd->add_option("--ns-prefix", ctl.ns_prefix, "with --vehicles: namespace prefix (default: swarm.namespace_prefix, /uav)");
  ctl_cmd->add_option("--threads", ctl.threads, "with --vehicles: threads, one DDS participant each")
      ->check(CLI::Range(1, 64));
  ctl_cmd->add_flag("--sensor-qos", ctl.sensor_qos, "subscribe Pose/Velocity/Imu best effort (ROS sensor data QoS)");
  add_cpus_option(ctl_cmd, ctl.cpus);
  ctl_cmd->add_flag("!--realtime", ctl.lockstep, "step on a wall-clock timer instead of lockstep");
  ctl_cmd->add_flag("!--no-schedule", ctl.apply_schedule,
                    "ignore the scenario's schedule (someone else sets the parameters)");
  ctl_cmd->add_option("--rate-factor", ctl.rate_factor, "real time: run the timer k times faster")
      ->check(CLI::Range(1e-3, 1e6));
  ctl_cmd->add_option("--rt-priority", ctl.rt_priority,
                      "real time: run the control loop under SCHED_FIFO at this priority (needs CAP_SYS_NICE)")
      ->check(CLI::Range(0, 99));
  ctl_cmd->add_option("--stats", ctl.stats, "real time: write the control period jitter as JSON here on exit");
  ctl_cmd->add_option("--node-name", ctl.node_name, "ROS node name: parameter services /NAME/..., ros2 node list")
      ->check(CLI::Validator(check_node_name, "NAME"));

  add_enclave_option(ctl_cmd, ctl.enclave);

  OpenloopOptions ol;
  auto* ol_cmd = app.add_subcommand("openloop", "the plant alone under a rotor speed schedule");
  ol_cmd->add_option("--commands", ol.commands, "CSV with header t,w1,w2,w3,w4 [s, rad/s]")
      ->required()->check(CLI::ExistingFile);
  ol_cmd->add_option("--out", ol.out, "trajectory CSV to write")->required();
  ol_cmd->add_option("--vehicle", ol.vehicle, "vehicle YAML (default: the paper's Table 1)")
      ->check(CLI::ExistingFile);
  ol_cmd->add_option("--rate-hz", ol.rate_hz, "plant rate [Hz]")->check(CLI::Range(1e-3, 1e6));
  ol_cmd->add_option("--substeps", ol.substeps, "RK4 steps per plant tick")->check(CLI::Range(1, 10000));
  ol_cmd->add_option("--duration", ol.duration_s, "simulated time [s] (default: last command time)")
      ->check(CLI::Range(0.0, 1e7));
  ol_cmd->add_option("--initial-z", ol.initial_z_m, "start at rest at this height [m]")
      ->check(CLI::Range(0.0, 1e6));

  LqrOptions lqr;
  auto* lqr_cmd = app.add_subcommand("lqr", "each attitude axis's A, B, Q, R, gain K and closed-loop poles");
  lqr_cmd->add_option("--params", lqr.params, "controller parameter YAML")->check(CLI::ExistingFile);
  lqr_cmd->add_option("--vehicle", lqr.vehicle, "vehicle YAML")->check(CLI::ExistingFile);

  ParamsOptions params;
  auto* params_cmd = app.add_subcommand("params", "list the controller's (or the vehicle's) parameters");
  params_cmd->add_flag("--vehicle", params.vehicle, "the vehicle's parameters (scenario `vehicle:`, vehicle files)");
  params_cmd->add_flag("--markdown", params.markdown, "the vehicle table as Markdown, as docs/model.md shows it")
      ->needs(params_cmd->get_option("--vehicle"));

  SummaryOptions sum;
  auto* sum_cmd = app.add_subcommand("summary", "table of step figures of several runs (ours beside the paper's)");
  sum_cmd->add_option("run_dirs", sum.run_dirs, "run directories (with metrics.json)")->required();
  sum_cmd->add_option("--out", sum.out, "also write the table to this Markdown file");

  TopicOptions topic;
  auto* topic_cmd = add_topic_subcommand(app, topic);

  ParamOptions param;
  auto* param_cmd = add_param_subcommand(app, param);

  std::string plot_dir;
  auto* plot_cmd = app.add_subcommand("plot", "regenerate a run directory's figures");
  plot_cmd->add_option("run_dir", plot_dir, "run directory (trajectory.csv, metrics.json)")
      ->required()->check(CLI::ExistingDirectory);

  std::string cmp_a, cmp_b, cmp_out;
  auto* cmp_cmd = app.add_subcommand("compare", "overlay two runs (e.g. two gain sets) and tabulate their step figures");
  cmp_cmd->add_option("run_a", cmp_a, "first run directory")->required()->check(CLI::ExistingDirectory);
  cmp_cmd->add_option("run_b", cmp_b, "second run directory")->required()->check(CLI::ExistingDirectory);
  cmp_cmd->add_option("--out", cmp_out, "output directory (default: RUN_B/compare_with_<RUN_A>)");

  RecordOptions rec;
  auto* rec_cmd = app.add_subcommand("record", "record a vehicle's topics over DDS into MCAP (like ros2 bag record)");
  rec_cmd->add_option("--out", rec.out, "MCAP file to write (metadata.yaml beside it)")->required();
  rec_cmd->add_option("--namespace", rec.ns, "the vehicle's namespace");
  rec_cmd->add_option("--topics", rec.topics, "only these topics (default: /clock and all of the vehicle's)");
  rec_cmd->add_option("--duration", rec.duration_s, "stop after this many seconds (default: Ctrl-C)")
      ->check(CLI::Range(0.0, 1e9));

  add_enclave_option(rec_cmd, rec.enclave);

  SecurityOptions sec;
  auto* sec_cmd = add_security_subcommand(app, sec);
  SweepOptions sweep;
  auto* sweep_cmd = add_sweep_subcommand(app, sweep);
  MarginsOptions margins;
  auto* margins_cmd = add_margins_subcommand(app, margins);

  BenchOptions bench;
  bench.scenario = QUADCOSIM_SCENARIOS_DIR "/paper/altitude_step.yaml";
  bench.swarm_scenario = QUADCOSIM_SCENARIOS_DIR "/swarm/grid_takeoff.yaml";
  auto* bench_cmd = app.add_subcommand("bench", "measure speed: in-process, DDS lockstep, real-time jitter, swarms");
  bench_cmd->add_flag("--json", bench.json, "print one JSON object");
  bench_cmd->add_flag("--quick", bench.quick, "short runs (smoke test; the figures are not representative)");
  bench_cmd->add_option("--only", bench.only, "run one part")
      ->check(CLI::IsMember({"inproc", "dds", "realtime", "swarm_inproc", "swarm_dds"}));
  bench_cmd->add_option("--seconds", bench.seconds, "simulated seconds of the inproc/dds part")
      ->check(CLI::Range(0.0, 1e6));
  bench_cmd->add_option("--rt-priority", bench.rt_priority, "realtime part: SCHED_FIFO priority of the controller (0: skip)")
      ->check(CLI::Range(0, 99));
  bench_cmd->add_option("--scenario", bench.scenario, "single-vehicle scenario")->check(CLI::ExistingFile);
  bench_cmd->add_option("--swarm-scenario", bench.swarm_scenario, "swarm scenario")->check(CLI::ExistingFile);

  // Bad flags and arguments: CLI11's message (it names the flag, the value and what was expected) and
  // exit 2, as for every other bad input; --help and --version exit 0.
  if (const std::string first = unknown_first_argument(app, argc, argv); !first.empty()) {
    std::string names;
    for (const CLI::App* sub : app.get_subcommands({})) names += (names.empty() ? "" : ", ") + sub->get_name();
    std::cerr << "error: " << (first[0] == '-' ? "unknown option '" : "unknown command '") << first
              << "'; expected a command: " << names << "\nRun with --help for more information.\n";
    return 2;
  }
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    return app.exit(e) == 0 ? 0 : 2;
  }
  if (*bench_cmd) return bench_command(bench);
  if (*sec_cmd) return security_command(sec);
  if (*sweep_cmd) return sweep_command(sweep);
  if (*margins_cmd) return margins_command(margins);
  if (*rec_cmd) return record_command(rec);
  if (*plot_cmd) return plot_command(plot_dir);
  if (*cmp_cmd) return compare_command(cmp_a, cmp_b, cmp_out);
  if (*run_cmd) return run_command(run);
  if (*plant_cmd) return plant_command(plant);
  if (*ctl_cmd) return controller_command(ctl);
  if (*ol_cmd) return openloop_command(ol);
  if (*lqr_cmd) return lqr_command(lqr);
  if (*params_cmd) return params_command(params);
  if (*sum_cmd) return summary_command(sum);
  if (*topic_cmd) return topic_command(topic);
  if (*param_cmd) return param_command(param);
  return 2;
}
