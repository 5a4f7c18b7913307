// quadcosim: one binary, one subcommand per job.
#include <CLI/CLI.hpp>

#include "app/commands.hpp"

int main(int argc, char** argv) {
  using namespace quadcosim::app;
  CLI::App app{"quadcosim: quadrotor flight-controller co-simulation (plant + ROS 2-style controller)"};
  app.require_subcommand(1);
  app.set_version_flag("--version", std::string("quadcosim ") + QUADCOSIM_VERSION);

  RunOptions run;
  auto* run_cmd = app.add_subcommand("run", "run a scenario: trajectory.csv, metrics.json, plots");
  run_cmd->add_option("scenario", run.scenario, "scenario YAML file")->required()->check(CLI::ExistingFile);
  run_cmd->add_option("--out", run.out_dir, "output directory (created)")->required();
  run_cmd->add_flag("!--no-plots", run.plots, "skip the PNG plots");

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

  auto* params_cmd = app.add_subcommand("params", "list the controller's parameters");

  SummaryOptions sum;
  auto* sum_cmd = app.add_subcommand("summary", "table of step figures of several runs (ours beside the paper's)");
  sum_cmd->add_option("run_dirs", sum.run_dirs, "run directories (with metrics.json)")->required();
  sum_cmd->add_option("--out", sum.out, "also write the table to this Markdown file");

  CLI11_PARSE(app, argc, argv);
  if (*run_cmd) return run_command(run);
  if (*ol_cmd) return openloop_command(ol);
  if (*lqr_cmd) return lqr_command(lqr);
  if (*params_cmd) return params_command();
  if (*sum_cmd) return summary_command(sum);
  return 2;
}
