// quadcosim: one binary, one subcommand per job. Each command file registers its subcommand
// (add_<name>_subcommand); main creates the app, parses, and runs the chosen command under the one
// mapping of errors to exit codes (exit_codes.hpp).
#include <CLI/CLI.hpp>

#include <cctype>
#include <functional>
#include <iostream>
#include <string>
#include <vector>

#include "app/commands.hpp"
#include "app/exit_codes.hpp"
#include "hosts/scenario_resolvers.hpp"
#include "io/scenario_limits.hpp"
#include "python/embedded/python_host.hpp"
#include "util/did_you_mean.hpp"

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

// The first option on the command line that the chosen command does not know, as an error naming the
// nearest option it does know ("" when every option is known). CLI11 checks required options and
// arguments before leftovers, so `run S --outt o` would otherwise say "--out is required" and hide the
// typo.
std::string unknown_option(const CLI::App& app) {
  const CLI::App* command = &app;
  while (!command->get_subcommands().empty()) command = command->get_subcommands().front();
  for (const std::string& arg : app.remaining(true)) {
    // Not options: the end-of-options mark, a lone dash, a negative number.
    if (arg.size() < 2 || arg[0] != '-' || arg == "--" || std::isdigit(static_cast<unsigned char>(arg[1]))) continue;
    const std::string given = arg.substr(0, arg.find('='));
    const std::size_t dashes = given.find_first_not_of('-');
    std::vector<std::string> known;
    for (const CLI::Option* o : command->get_options()) {
      for (const std::string& name : o->get_lnames()) known.push_back("--" + name);
      for (const std::string& name : o->get_snames()) known.push_back("-" + name);
    }
    // Compared without their dashes: "--outt" is one letter from "--out", not one in six.
    std::vector<std::string> bare;
    for (const std::string& k : known) bare.push_back(k.substr(k.find_first_not_of('-')));
    const std::string near =
        quadcosim::util::nearest_name(given.substr(dashes == std::string::npos ? 0 : dashes), bare);
    std::string hint;
    for (std::size_t i = 0; i < bare.size() && !near.empty(); ++i) {
      if (bare[i] == near) {
        hint = "; did you mean '" + known[i] + "'?";
        break;
      }
    }
    return command->get_name() + ": unknown option '" + given + "'" + hint;
  }
  return {};
}

}  // namespace

int main(int argc, char** argv) {
  using namespace quadcosim::app;
  CLI::App app{"quadcosim: quadrotor flight-controller co-simulation (plant + ROS 2-style controller)"};
  app.require_subcommand(1);
  app.set_version_flag("--version", std::string("quadcosim ") + QUADCOSIM_VERSION);

  RunOptions run;
  PlantCommandOptions plant;
  ControllerCommandOptions controller;
  OpenloopOptions openloop;
  LqrOptions lqr;
  ParamsOptions params;
  SummaryOptions summary;
  TopicOptions topic;
  ParamOptions param;
  PlotOptions plot;
  CompareOptions compare;
  RecordOptions record;
  SecurityOptions security;
  SweepOptions sweep;
  MarginsOptions margins;
  BenchOptions bench;
  FmuOptions fmu;
  // What makes the FMUs and Python classes the scenarios name: the FMUs through a loader this process
  // owns for its life, Python classes through the embedded interpreter (started on first use only).
  const quadcosim::io::ScenarioResolvers resolvers = quadcosim::hosts::scenario_resolvers(
      quadcosim::embedded_python::python_controller_factory(), quadcosim::embedded_python::python_module_file);
  struct Subcommand {
    CLI::App* cli;
    std::function<int()> run;
  };
  const std::vector<Subcommand> commands = {
      {add_run_subcommand(app, run), [&] { return run_command(run, resolvers); }},
      {add_plant_subcommand(app, plant), [&] { return plant_command(plant, resolvers); }},
      {add_controller_subcommand(app, controller), [&] { return controller_command(controller, resolvers); }},
      {add_openloop_subcommand(app, openloop), [&] { return openloop_command(openloop); }},
      {add_lqr_subcommand(app, lqr), [&] { return lqr_command(lqr, resolvers); }},
      {add_params_subcommand(app, params), [&] { return params_command(params, resolvers); }},
      {add_summary_subcommand(app, summary), [&] { return summary_command(summary); }},
      {add_topic_subcommand(app, topic), [&] { return topic_command(topic); }},
      {add_param_subcommand(app, param), [&] { return param_command(param); }},
      {add_plot_subcommand(app, plot), [&] { return plot_command(plot); }},
      {add_compare_subcommand(app, compare), [&] { return compare_command(compare); }},
      {add_record_subcommand(app, record), [&] { return record_command(record); }},
      {add_security_subcommand(app, security), [&] { return security_command(security); }},
      {add_sweep_subcommand(app, sweep), [&] { return sweep_command(sweep, resolvers); }},
      {add_margins_subcommand(app, margins), [&] { return margins_command(margins, resolvers); }},
      {add_bench_subcommand(app, bench), [&] { return bench_command(bench, resolvers); }},
      {add_fmu_subcommand(app, fmu), [&] { return fmu_command(fmu, resolvers); }},
  };
  add_exit_code_footers(app);
  // Limits on what files and flags may ask for (io/scenario_limits.hpp), on the commands that read
  // scenarios and FMUs.
  bool no_limits = false;
  std::vector<std::string> limit_overrides;
  for (const char* name : {"run", "plant", "controller", "sweep", "fmu"}) {
    CLI::App* sub = app.get_subcommand(name);
    sub->add_flag("--no-limits", no_limits,
                  "lift every limit on scenarios, FMUs, outputs and swarms (docs/scenarios.md, \"Limits\")");
    sub->add_option("--limit", limit_overrides,
                    "raise one limit: NAME=VALUE (repeatable; scenario_bytes, schedule_entries, plant_rate_hz, "
                    "fmu_entries, fmu_unpacked_bytes, fmu_variables)")
        ->allow_extra_args(false);
  }

  // Bad flags and arguments: CLI11's message (it names the flag, the value and what was expected) and
  // exit 2, as for every other bad input; --help and --version exit 0.
  if (const std::string first = unknown_first_argument(app, argc, argv); !first.empty()) {
    std::string names;
    for (const CLI::App* sub : app.get_subcommands({})) names += (names.empty() ? "" : ", ") + sub->get_name();
    std::cerr << "error: " << (first[0] == '-' ? "unknown option '" : "unknown command '") << first
              << "'; expected a command: " << names << "\nRun with --help for more information.\n";
    return exit_code::kBadInput;
  }
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    if (const std::string unknown = unknown_option(app); e.get_exit_code() != 0 && !unknown.empty()) {
      std::cerr << "error: " << unknown << "\nRun with --help for more information.\n";
      return exit_code::kBadInput;
    }
    return app.exit(e) == 0 ? exit_code::kOk : exit_code::kBadInput;
  }
  {
    quadcosim::io::Limits limits;
    limits.enabled = !no_limits;
    for (const std::string& a : limit_overrides) {
      if (const std::string err = quadcosim::io::apply_limit(limits, a); !err.empty()) {
        std::cerr << "error: " << err << '\n';
        return exit_code::kBadInput;
      }
    }
    quadcosim::io::set_limits(limits);
  }
  for (const Subcommand& c : commands) {
    if (*c.cli) {
      const int code = run_guarded(c.cli->get_name(), c.run);
      quadcosim::embedded_python::python_at_exit();
      return code;
    }
  }
  return exit_code::kBadInput;
}
