// `quadcosim sweep SCENARIO --runs N --seed S --vary KEY=DIST ... --out DIR` and its `rerun` and
// `merge` subcommands: flags, the sweep folder's files and console text; flying the runs and saying
// the summary is hosts/sweep_runs.hpp's, drawing, running and summarising one run the sweep library's
// (src/sweep/, docs/sweeps.md).
#include <fmt/format.h>

#include <unistd.h>
#include <CLI/CLI.hpp>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <nlohmann/json.hpp>
#include <optional>
#include <set>
#include <sstream>

#include "app/commands.hpp"
#include "app/exit_codes.hpp"
#include "hosts/node_common.hpp"
#include "hosts/signals.hpp"
#include "hosts/sweep_runs.hpp"
#include "io/output_folder.hpp"
#include "io/scenario.hpp"
#include "io/step_report.hpp"
#include "sweep/sweep.hpp"

namespace quadcosim::app {

namespace fs = std::filesystem;

namespace {

std::string read_file(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw std::runtime_error(path.string() + ": cannot read");
  std::ostringstream text;
  text << in.rdbuf();
  return text.str();
}

// A copy of `from` at `to`, written atomically and never through a link at `to`.
void copy_output(const fs::path& from, const fs::path& to) { io::write_file_atomically(to, read_file(from)); }

bool parse_shard(const std::string& text, int& k, int& n) {
  const auto slash = text.find('/');
  if (slash == std::string::npos) return false;
  try {
    std::size_t a = 0, b = 0;
    k = std::stoi(text.substr(0, slash), &a);
    n = std::stoi(text.substr(slash + 1), &b);
    return a == slash && b == text.size() - slash - 1 && n >= 1 && k >= 1 && k <= n;
  } catch (const std::exception&) {
    return false;
  }
}

// Makes PYTHONPATH what the sweep in `dir` recorded (origin.json) ahead of the current one, before
// anything starts Python, so that a Python controller is imported from where the sweep imported it,
// whatever the current directory. Returns the record (nullopt: none, a sweep of an older quadcosim).
std::optional<sweep::Origin> use_origin(const fs::path& dir) {
  std::optional<sweep::Origin> origin = sweep::read_origin(dir);  // io::ConfigError names the file
  if (origin) setenv("PYTHONPATH", sweep::python_path_env(*origin, std::getenv("PYTHONPATH")).c_str(), 1);
  return origin;
}

// The scenario_file the sweep in `dir` recorded in its summary.json or shard.json ("" when unreadable:
// finished_runs then says what is wrong).
std::string recorded_scenario_file(const fs::path& dir, const std::string& shard) {
  try {
    const nlohmann::json j = nlohmann::json::parse(read_file(dir / (shard.empty() ? "summary.json" : "shard.json")));
    const nlohmann::json& h = shard.empty() ? j : j.at("header");
    return h.at("scenario_file").get<std::string>();
  } catch (const std::exception&) {
    return {};
  }
}

// index.html of a sweep folder (tools/sweep_index.py), after the plots it shows.
bool make_index(const std::string& dir) { return run_tool("sweep_index.py", {dir}); }

int rerun_command(const SweepOptions& o, const io::ScenarioResolvers& resolvers) {
  sweep::Plan plan;
  try {
    (void)use_origin(o.sweep_dir);
    plan = sweep::plan_of(o.sweep_dir, resolvers);
  } catch (const std::runtime_error& e) {  // names the file: not a sweep folder, or not this one's
    std::cerr << "error: " << e.what() << '\n';
    return exit_code::kBadInput;
  }
  if (o.rerun_index < 0 || o.rerun_index >= plan.runs) {
    std::cerr << fmt::format("error: sweep rerun: run {} is not in {} (runs 0..{})\n", o.rerun_index, o.sweep_dir,
                             plan.runs - 1);
    return exit_code::kBadInput;
  }
  io::OutputFolder folder = io::OutputFolder::claim(o.out_dir, "sweep rerun", {.force = o.force}, std::cerr);
  const fs::path out(o.out_dir);
  return run_guarded(fmt::format("sweep run {}", o.rerun_index), [&] {
    copy_output(fs::path(o.sweep_dir) / "scenario.yaml", out / "scenario.yaml");
    const sweep::RunResult r = sweep::rerun(plan, o.rerun_index, out);
    std::ifstream txt(out / "metrics.txt");
    std::cout << fmt::format("sweep run {} (seed {}):", o.rerun_index, r.sample.seed);
    for (const auto& [k, v] : r.sample.values) std::cout << fmt::format(" {}={}", k, v);
    std::cout << '\n' << txt.rdbuf();
    std::cout << "wrote " << (out / "trajectory.csv").string()
              << ", run.mcap, metadata.yaml, metrics.json, metrics.txt\n";
    if (o.plots && !make_plots(o.out_dir, folder)) return exit_code::kOutput;
    return r.passed ? exit_code::kOk : exit_code::kFailed;
  });
}

int merge_command(const SweepOptions& o) {
  nlohmann::json header;
  std::vector<nlohmann::json> per_run;
  for (const std::string& dir : o.shard_dirs) {
    const fs::path file = fs::path(dir) / "shard.json";
    std::ifstream in(file);
    if (!in) {
      std::cerr << "error: " << file.string() << ": not found (not a shard folder)\n";
      return exit_code::kBadInput;
    }
    nlohmann::json j;
    try {
      j = nlohmann::json::parse(in);
      sweep::check_shard_json(j);
    } catch (const nlohmann::json::parse_error& e) {
      std::cerr << "error: " << file.string() << ": not JSON (" << e.what() << ")\n";
      return exit_code::kBadInput;
    } catch (const std::invalid_argument& e) {  // check_shard_json: the field and what it holds
      std::cerr << "error: " << file.string() << ": not a shard's results: " << e.what() << '\n';
      return exit_code::kBadInput;
    }
    if (j.contains("partial")) {
      std::cerr << fmt::format(
          "error: {}: shard {} was interrupted ({} of its runs finished); finish it first with its `quadcosim "
          "sweep ... --shard {} --out {} --resume`\n",
          file.string(), j.value("shard", std::string("?")), j["per_run"].size(), j.value("shard", std::string("K/N")),
          dir);
      return exit_code::kBadInput;
    }
    if (header.is_null()) {
      header = j["header"];
    } else if (j["header"] != header) {
      std::cerr << "error: " << file.string() << ": a shard of another sweep (scenario, seed, runs or --vary differ "
                << "from " << o.shard_dirs.front() << ")\n";
      return exit_code::kBadInput;
    }
    for (auto& r : j["per_run"]) per_run.push_back(std::move(r));
  }
  // A run missing or given twice: std::invalid_argument, bad input (run_guarded).
  const nlohmann::json summary = sweep::summary_json(header, std::move(per_run));
  const fs::path out(o.out_dir);
  io::OutputFolder folder = io::OutputFolder::claim(out, "sweep merge", {.force = o.force}, std::cerr);
  copy_output(fs::path(o.shard_dirs.front()) / "scenario.yaml", out / "scenario.yaml");
  // The first shard's origin, so that `sweep rerun` of the merged folder finds what its scenario needs.
  if (fs::is_regular_file(fs::path(o.shard_dirs.front()) / sweep::kOriginFile))
    copy_output(fs::path(o.shard_dirs.front()) / sweep::kOriginFile, out / sweep::kOriginFile);
  sweep::write_json(out / "summary.json", summary);  // a write failure: exit 3 naming the file (run_guarded)
  hosts::print_sweep_summary(summary, std::cout);
  std::cout << "wrote " << (out / "summary.json").string() << " from " << o.shard_dirs.size() << " shards\n";
  if (o.plots && !(run_tool("plot_sweep.py", {o.out_dir}) && make_index(o.out_dir))) return exit_code::kOutput;
  return hosts::sweep_verdict(summary, o.min_pass_rate, std::cerr);
}

}  // namespace

CLI::App* add_sweep_subcommand(CLI::App& app, SweepOptions& o) {
  auto* c = app.add_subcommand("sweep", "Runs of a scenario with varied keys and seeded noise (docs/sweeps.md)");
  c->add_option("scenario", o.scenario, "scenario YAML file")->check(CLI::ExistingFile);
  c->add_option("--runs", o.runs, "number of runs; with a grid, runs per grid point (default 1 then)")
      ->check(CLI::Range(1, 10000000))
      ->each([&o](const std::string&) { o.runs_given = true; });
  c->add_option("--seed", o.seed, "sweep seed (run i's seed and values derive from it)");
  c->add_option("--vary", o.vary,
                "KEY=P% | KEY=uniform(a,b) | KEY=normal(mu,sigma) | KEY=grid(v1,...) | KEY=linspace(a,b,n); KEY "
                "is a scenario key by its YAML path (controller.altitude.kp, vehicle.mass_kg, ...) or an alias "
                "(mass, inertia, kt, ...) (repeatable)");
  c->add_option("--sampler", o.sampler, "random, or lhs: Latin hypercube over the random keys")
      ->check(CLI::IsMember({"random", "lhs"}));
  c->add_option("--keep", o.keep, "keep trajectory.csv of none, failing or all runs")
      ->check(CLI::IsMember({"none", "failing", "all"}));
  c->add_option("--shard", o.shard, "K/N: run the runs i with i % N == K-1 and write shard.json for `sweep merge`");
  c->add_flag("--force", o.force,
              "--out holds a previous command's outputs or other files: remove exactly the outputs its manifest "
              "lists first (files quadcosim did not write are kept)");
  c->add_flag("--resume", o.resume,
              "finish the interrupted sweep in --out (same scenario and options): run only its missing runs");
  c->add_option("--out", o.out_dir, "output directory: new or empty (created when missing)");
  c->add_option("--jobs", o.jobs, "parallel runs (threads)")->check(CLI::Range(1, 64));
  c->add_option("--min-pass-rate", o.min_pass_rate, "exit 1 when fewer runs than this fraction pass")
      ->check(CLI::Range(0.0, 1.0));
  c->add_flag("!--no-plots", o.plots, "skip the plots and index.html");
  c->add_flag("!--no-progress", o.progress, "no progress on stderr while the runs go");
  c->add_option("--progress-every", o.progress_every_s,
                "seconds between progress lines when stderr is not a terminal (0: after each run; default 5)")
      ->check(CLI::Range(0.0, 1e6));
  add_judge_option(*c, o.judge);

  auto* r = c->add_subcommand("rerun", "fly run I of a sweep again with the outputs of `run`");
  r->add_option("dir", o.sweep_dir, "sweep folder (summary.json or shard.json, scenario.yaml)")->required();
  r->add_option("index", o.rerun_index, "run index")->required();
  r->add_option("--out", o.out_dir, "run folder: new or empty (created when missing)")->required();
  r->add_flag("--force", o.force,
              "--out is not empty: remove the outputs its manifest lists first (other files are kept)");
  r->add_flag("!--no-plots", o.plots, "skip the plots and report");
  r->callback([&o] { o.mode = "rerun"; });

  auto* m = c->add_subcommand("merge", "join the shards of a sweep into one summary.json");
  m->add_option("out", o.out_dir, "output folder: new or empty (created when missing)")->required();
  m->add_option("dirs", o.shard_dirs, "shard folders (each with shard.json)")->required();
  m->add_flag("--force", o.force,
              "OUT is not empty: remove the outputs its manifest lists first (other files are kept)");
  m->add_option("--min-pass-rate", o.min_pass_rate, "exit 1 when fewer runs than this fraction pass")
      ->check(CLI::Range(0.0, 1.0));
  m->add_flag("!--no-plots", o.plots, "skip the plots and index.html");
  m->callback([&o] { o.mode = "merge"; });
  return c;
}

int sweep_command(const SweepOptions& o, const io::ScenarioResolvers& resolvers) {
  if (o.mode == "rerun") return rerun_command(o, resolvers);
  if (o.mode == "merge") return merge_command(o);
  if (o.scenario.empty() || o.out_dir.empty()) {
    std::cerr << "error: sweep: give a SCENARIO and --out DIR (or `sweep rerun`, `sweep merge`; see --help)\n";
    return exit_code::kBadInput;
  }
  int shard = 1, shards = 1;
  if (!o.shard.empty() && !parse_shard(o.shard, shard, shards)) {
    std::cerr << "error: --shard " << o.shard << ": expected K/N with 1 <= K <= N (e.g. 2/8)\n";
    return exit_code::kBadInput;
  }
  // A bad --vary or scenario: io::ConfigError or std::invalid_argument, bad input (run_guarded).
  bool grid = false;
  for (const auto& spec : o.vary) grid = grid || sweep::parse_vary(spec).distribution == sweep::Distribution::kGrid;
  const fs::path out(o.out_dir);
  // --resume continues the sweep where it was started: its scenario is loaded as if from the recorded
  // file (what it names relative to its folder is found there) and Python imports from the folders
  // it imported from, whatever the current directory; the header keeps the scenario path as first
  // typed (the file is checked to be the same bytes below).
  std::optional<sweep::Origin> origin;
  std::string recorded_file;
  if (o.resume && fs::is_directory(out)) {
    origin = use_origin(out);
    recorded_file = recorded_scenario_file(out, o.shard);
  }
  sweep::Plan plan = sweep::make_plan(o.scenario, o.vary, o.seed, grid && !o.runs_given ? 1 : o.runs,
                                      o.sampler == "lhs" ? sweep::Sampler::kLhs : sweep::Sampler::kRandom, resolvers,
                                      origin ? sweep::scenario_source_of(*origin) : std::string());
  if (!recorded_file.empty()) {
    plan.scenario_file = recorded_file;
    plan.nominal.path = recorded_file;
  }
  plan.judge = io::parse_judge(o.judge).value_or(io::Judge::kSpec);  // --judge checked its value
  if (const std::string note = io::nothing_judged_note(plan.nominal, plan.judge); !note.empty()) {
    std::cout << "sweep " << plan.nominal.name << ": " << note << '\n';
  }
  if (plan.nominal.steps.empty() && !plan.nominal.hold && !plan.nominal.tracking) {
    std::cerr << "error: " << o.scenario << ": analysis: the scenario has no steps, no hold criterion and no "
              << "trajectory to track; a sweep needs something to judge\n";
    return exit_code::kBadInput;
  }
  if (o.resume && o.force) {
    std::cerr << "error: sweep: --resume finishes the sweep in --out, --force starts a new one there: give one\n";
    return exit_code::kBadInput;
  }
  const nlohmann::json header = sweep::header_json(plan);
  std::vector<nlohmann::json> per_run;  // the runs finished before (--resume), then these
  std::optional<io::OutputFolder> folder;
  if (o.resume) {
    folder.emplace(io::OutputFolder::resume(out, "sweep"));
    if (!fs::is_regular_file(out / "scenario.yaml") || read_file(o.scenario) != read_file(out / "scenario.yaml")) {
      std::cerr << fmt::format(
          "error: sweep --resume: {} differs from the scenario the sweep in {} flew ({}); resume "
          "with that file, or start this one in another folder\n",
          o.scenario, out.string(), (out / "scenario.yaml").string());
      return exit_code::kBadInput;
    }
    bool complete = false;
    per_run = sweep::finished_runs(out, header, o.shard, complete);  // bad input: names the file
    if (complete) {
      std::cout << fmt::format("sweep {}: {} already holds all its runs; nothing to resume\n", plan.nominal.name,
                               out.string());
      if (!o.shard.empty()) return exit_code::kOk;
      const nlohmann::json summary = nlohmann::json::parse(read_file(out / "summary.json"));
      hosts::print_sweep_summary(summary, std::cout);
      return hosts::sweep_verdict(summary, o.min_pass_rate, std::cerr);
    }
  } else {
    // --force removes the runs the previous sweep's manifest lists; runs/ files no manifest lists
    // (an older quadcosim's interrupted sweep) are refused rather than kept beside the new runs.
    folder.emplace(io::OutputFolder::claim(out, "sweep", {.force = o.force, .exclusive = {"runs"}}, std::cerr));
    copy_output(o.scenario, out / "scenario.yaml");
    sweep::write_json(out / sweep::kOriginFile,
                      sweep::origin_json(sweep::origin_of(o.scenario, fs::current_path(), std::getenv("PYTHONPATH"))));
  }
  const sweep::Keep keep = o.keep == "all"       ? sweep::Keep::kAll
                           : o.keep == "failing" ? sweep::Keep::kFailing
                                                 : sweep::Keep::kNone;
  const hosts::SweepRunsDone runs = hosts::fly_sweep_runs(plan, shard, shards, out,
                                                          {.jobs = o.jobs,
                                                           .keep = keep,
                                                           .resume = o.resume,
                                                           .progress = o.progress,
                                                           .progress_every_s = o.progress_every_s},
                                                          *folder, per_run, std::cout, std::cerr);
  const bool interrupted = runs.interrupted;
  const std::string resume_hint = "finish it with the same command and --resume instead of --force";
  if (!o.shard.empty()) {
    const std::size_t expected = runs.expected;
    int passed = 0;
    for (const auto& r : per_run) passed += r.at("passed").get<bool>() ? 1 : 0;
    nlohmann::json j = {{"header", header}, {"shard", o.shard}, {"per_run", per_run}};
    if (interrupted) j["partial"] = {{"finished", per_run.size()}, {"runs", expected}};
    sweep::write_json(out / "shard.json", j);
    if (interrupted) {
      std::cout << fmt::format("sweep {} shard {}: interrupted: {} of its {} runs finished ({} passed); wrote {}; {}\n",
                               plan.nominal.name, o.shard, per_run.size(), expected, passed,
                               (out / "shard.json").string(), resume_hint);
      return exit_code::kInterrupted;
    }
    std::cout << fmt::format(
        "sweep {} shard {}: {} of {} runs ({} passed); wrote {} and runs/NNNN/metrics.json; "
        "join the shards with `quadcosim sweep merge OUT DIR...`\n",
        plan.nominal.name, o.shard, per_run.size(), plan.runs, passed, (out / "shard.json").string());
    return hosts::stop_requested() ? exit_code::kInterrupted : exit_code::kOk;
  }
  if (interrupted) {
    const nlohmann::json summary = sweep::partial_summary_json(header, std::move(per_run));
    sweep::write_json(out / "summary.json", summary);
    hosts::print_sweep_summary(summary, std::cout);
    std::cout << fmt::format("wrote {} (partial) and runs/NNNN/metrics.json; {}\n", (out / "summary.json").string(),
                             resume_hint);
    return exit_code::kInterrupted;
  }
  const nlohmann::json summary = sweep::summary_json(header, std::move(per_run));
  sweep::write_json(out / "summary.json", summary);  // a write failure: exit 3 naming the file (run_guarded)
  hosts::print_sweep_summary(summary, std::cout);
  std::cout << "wrote " << (out / "summary.json").string() << " and runs/NNNN/metrics.json\n";
  if (hosts::stop_requested()) return exit_code::kInterrupted;  // every run finished; no plots
  if (o.plots && !(run_tool("plot_sweep.py", {o.out_dir}) && make_index(o.out_dir))) return exit_code::kOutput;
  return hosts::sweep_verdict(summary, o.min_pass_rate, std::cerr);
}

}  // namespace quadcosim::app
