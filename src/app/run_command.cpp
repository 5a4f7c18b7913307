// `quadcosim run SCENARIO --out DIR`: the flags, the output folder, the provenance and the verdict
// line; flying is hosts/inprocess_run.hpp's (in process), hosts/dds_run.hpp's (over DDS) and
// swarm_run.cpp's (swarms).
#include <fmt/format.h>
#include <CLI/CLI.hpp>

#include <stdlib.h>
#include <unistd.h>

#include <yaml-cpp/yaml.h>
#include <chrono>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <optional>

#include "app/commands.hpp"
#include "app/exit_codes.hpp"
#include "app/foxglove_cli.hpp"
#include "app/swarm.hpp"
#include "control/care.hpp"
#include "hosts/dds_run.hpp"
#include "hosts/inprocess_run.hpp"
#include "hosts/node_common.hpp"
#include "hosts/signals.hpp"
#include "io/mcap_recorder.hpp"
#include "io/output_folder.hpp"
#include "io/provenance.hpp"
#include "io/scenario.hpp"
#include "io/scenario_limits.hpp"
#include "io/step_report.hpp"
#include "io/trajectory_csv.hpp"
#include "sim/simulation.hpp"

namespace quadcosim::app {

namespace fs = std::filesystem;

namespace {

// A progress line on stderr for runs that take a while, only when stderr is a terminal.
class Progress {
 public:
  explicit Progress(double total_s)
      : total_s_(total_s), tty_(isatty(STDERR_FILENO) == 1), start_(std::chrono::steady_clock::now()), last_(start_) {}
  void update(double t_s) {
    if (!tty_) return;
    const auto now = std::chrono::steady_clock::now();
    if (now - last_ < std::chrono::milliseconds(200) || now - start_ < std::chrono::milliseconds(500)) return;
    last_ = now;
    const double wall = std::chrono::duration<double>(now - start_).count();
    std::cerr << fmt::format("\r  t = {:.1f} / {:.1f} s simulated ({:.0f}x real time)   ", t_s, total_s_, t_s / wall)
              << std::flush;
    shown_ = true;
  }
  void done() {
    if (shown_) std::cerr << '\n';
  }

 private:
  double total_s_;
  bool tty_;
  std::chrono::steady_clock::time_point start_, last_;
  bool shown_ = false;
};

// The run's provenance record (io/provenance.hpp): made once, written into metadata.yaml, metrics.json
// and (through them) the report and plots.
nlohmann::json run_provenance(const RunOptions& opt, const io::Scenario& flown,
                              const io::ScenarioResolvers& resolvers) {
  YAML::Node root = YAML::LoadFile(opt.scenario);  // read by load_scenario already
  if (!opt.controller.empty()) io::set_controller_type(root, opt.controller);
  return io::describe_run(flown, {.transport = opt.transport,
                                  .clock = opt.transport == "dds" && opt.realtime ? "realtime" : "lockstep",
                                  .controller_override = opt.controller,
                                  .python_target = io::python_target_of(root),
                                  .python_module = resolvers.python_module});
}

// "run: FAILED against spec: z overshoot_pct 30.2 outside [-, 25]; ...": the judged criteria that failed,
// each named by its block and figure, so the exit code 1 comes with its reason on one line.
std::string failed_criteria_line(const hosts::RunJudgement& j) {
  std::vector<std::string> failed;
  const auto add = [&](const std::string& block, const std::vector<io::CriterionResult>& criteria) {
    for (const auto& c : criteria) {
      if (!c.judged || c.passed) continue;
      const auto bound = [](const std::optional<double>& b) { return b ? fmt::format("{:g}", *b) : "-"; };
      failed.push_back(fmt::format("{} {} {} outside the {} band [{}, {}]", block, c.criterion.figure,
                                   c.value ? fmt::format("{:.4g}", *c.value) : "(none)", io::to_string(c.criterion.set),
                                   bound(c.criterion.min), bound(c.criterion.max)));
    }
  };
  for (const auto& s : j.steps) add("step " + s.spec.channel, s.criteria);
  if (j.hold) add("hold", j.hold->criteria);
  if (j.saturation) add("limits", j.saturation->criteria);
  if (j.tracking) add("tracking", j.tracking->criteria);
  std::string line = fmt::format("run: FAILED against {}:", io::to_string(j.judge));
  for (std::size_t i = 0; i < failed.size(); ++i) line += (i == 0 ? " " : "; ") + failed[i];
  return line + "\n";
}

}  // namespace

CLI::App* add_run_subcommand(CLI::App& app, RunOptions& run) {
  auto* run_cmd = app.add_subcommand("run", "run a scenario: trajectory.csv, metrics.json, plots");
  run_cmd->add_option("scenario", run.scenario, "scenario YAML file")->required()->check(CLI::ExistingFile);
  run_cmd->add_option("--out", run.out_dir, "output directory: new or empty (created when missing)")->required();
  run_cmd->add_flag("--force", run.force,
                    "--out holds a previous command's outputs or other files: remove exactly the outputs its "
                    "manifest lists first (files quadcosim did not write are kept)");
  run_cmd->add_flag("!--no-plots", run.plots, "skip the PNG plots and report.html");
  add_controller_type_option(*run_cmd, run.controller);
  add_judge_option(*run_cmd, run.judge);
  run_cmd
      ->add_option("--transport", run.transport,
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
  run_cmd
      ->add_option("--vehicles", run.vehicles,
                   "a swarm of N vehicles on a grid (default: the scenario's swarm section)")
      ->check(CLI::Range(1, 10'000'000));
  run_cmd->add_option("--threads", run.threads, "in-process swarm: worker threads (default: swarm.threads, 2)")
      ->check(CLI::Range(1, 64));
  add_foxglove_options(*run_cmd, run.foxglove, /*inprocess=*/true);
  // Flags that do nothing in the chosen mode are refused (exit 2), naming the flag and the mode.
  run_cmd->parse_complete_callback([run_cmd, &run] {
    const bool dds = run.transport == "dds";
    const bool swarm = run.vehicles > 0;
    refuse_idle_flags(*run_cmd,
                      {
                          {"--realtime", dds, "--transport inproc; it needs --transport dds"},
                          {"--pin", dds, "--transport inproc; it needs --transport dds"},
                          {"--timeout", dds, "--transport inproc; it needs --transport dds"},
                          {"--keystore", dds, "--transport inproc; it needs --transport dds"},
                          {"--rate-factor", dds && run.realtime, "lockstep; it needs --transport dds --realtime"},
                          {"--threads", !dds, "--transport dds; it sets the in-process swarm's threads"},
                          {"--foxglove", !swarm, "--vehicles; one vehicle is served"},
                          {"--foxglove-wait", !dds, "--transport dds; the plant waits for its controller"},
                          {"--foxglove-pace", !dds, "--transport dds; use --realtime there"},
                      });
  });
  return run_cmd;
}

int run_command(const RunOptions& opt, const io::ScenarioResolvers& resolvers) {
  const io::Scenario sc = io::load_scenario(opt.scenario, opt.controller, resolvers);

  if (opt.transport == "dds" && sc.simulation.faults.active() && !(opt.vehicles > 0 || sc.swarm)) {
    std::cerr << "error: " << opt.scenario
              << ": message_faults: message loss and delay are injected by the "
                 "in-process transport only; over DDS use tc netem (docs/reliability.md)\n";
    return exit_code::kBadInput;
  }
  if ((opt.vehicles > 0 || sc.swarm) && !opt.foxglove.listen.empty()) {
    std::cerr << "error: --foxglove serves one vehicle; " << opt.scenario << " flies a swarm\n";
    return exit_code::kBadInput;
  }
  // Limits (io/scenario_limits.hpp): a swarm against the memory, one vehicle's outputs against the disk.
  if (opt.vehicles > 0 || sc.swarm) {
    io::check_swarm_fits(opt.vehicles > 0 ? opt.vehicles : sc.swarm->layout.vehicles);
  } else {
    const double ticks = static_cast<double>(sc.simulation.duration_ticks) + 1.0;
    io::check_output_fits(opt.scenario, opt.out_dir, ticks, ticks / sc.simulation.controller_divider);
  }
  // Refused (exit 2) when it holds anything, unless --force; every file written below is listed in
  // its manifest, also when the run is interrupted or fails.
  io::OutputFolder folder = io::OutputFolder::claim(opt.out_dir, "run", {.force = opt.force}, std::cerr);
  const fs::path out(opt.out_dir);

  try {  // the model's and the controller's checks of the scenario name no file: say which
    // The scenario as flown: the file, or with --controller applied.
    io::write_file_atomically(out / "scenario.yaml", io::effective_scenario_text(opt.scenario, opt.controller));
    const nlohmann::json provenance = run_provenance(opt, sc, resolvers);
    if (opt.vehicles > 0 || sc.swarm) return run_swarm(opt, sc, out, folder, provenance);
    const std::string csv_path = (out / "trajectory.csv").string();
    if (opt.transport == "dds") {
      const int rc = hosts::run_over_dds({.scenario = opt.scenario,
                                          .controller = opt.controller,
                                          .realtime = opt.realtime,
                                          .rate_factor = opt.rate_factor,
                                          .timeout_s = opt.timeout_s,
                                          .pin = opt.pin,
                                          .keystore = opt.keystore,
                                          .foxglove = opt.foxglove},
                                         csv_path);
      io::add_provenance_to_bag_metadata(out, provenance);  // the plant wrote it: what ran, also when stopped
      if (rc != 0) return rc;
    } else {
      hosts::install_stop_handlers();
      Progress progress(sc.simulation.plant.clock.seconds(sc.simulation.duration_ticks));
      // --foxglove: one more of the run's recorders (hosts/recording.hpp), served from the
      // simulation's transport; --foxglove-pace holds each tick back until its time on the wall clock.
      const auto on_tick = [&](double t_s) {
        progress.update(t_s);
        return hosts::stop_requested();
      };
      const bool completed = hosts::fly_inprocess(
          sc, out, std::cout, std::cerr, on_tick, [&] { progress.done(); }, opt.foxglove);
      io::add_provenance_to_bag_metadata(out, provenance);
      if (!completed) {
        // Everything recorded so far stays valid: the CSV is flushed, the MCAP file finished.
        std::cerr << "\nrun: interrupted; " << csv_path << " and run.mcap hold what ran\n";
        return exit_code::kInterrupted;
      }
    }

    // Both transports are judged from what was recorded: the exact doubles of trajectory.csv.
    const hosts::RunJudgement judged =
        hosts::judge_run(sc, out, io::parse_judge(opt.judge).value_or(io::Judge::kSpec), provenance);
    std::cout << judged.table;  // says what was judged, and once when the scenario has none of that set
    if (judged.saturation) {
      if (const std::string w = io::saturation_warning(*judged.saturation); !w.empty()) {
        std::cerr << "run: " << w << '\n';
      }
    }
    std::cout << "wrote " << (out / "trajectory.csv").string()
              << ", run.mcap, metadata.yaml, metrics.json, metrics.txt\n";
    if (opt.plots && !make_plots(opt.out_dir, folder)) return exit_code::kOutput;
    if (!judged.passed) std::cout << failed_criteria_line(judged);
    return judged.passed ? exit_code::kOk : exit_code::kFailed;
  } catch (const control::CareError& e) {
    throw io::ConfigError(opt.scenario + ": controller design failed: " + e.what());
  } catch (const std::invalid_argument& e) {
    throw io::ConfigError(opt.scenario + ": " + e.what());
  }
}

}  // namespace quadcosim::app
