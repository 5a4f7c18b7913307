// `quadcosim sweep SCENARIO --runs N --seed S --vary KEY=DIST ... --out DIR` and its `rerun` and
// `merge` subcommands: flags and console text only; drawing, running and summarising the runs is the
// sweep library's (src/sweep/, docs/sweeps.md).
#include <fmt/format.h>

#include <CLI/CLI.hpp>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <nlohmann/json.hpp>

#include "app/commands.hpp"
#include "app/exit_codes.hpp"
#include "io/output_folder.hpp"
#include "io/scenario.hpp"
#include "io/step_report.hpp"
#include "sweep/sweep.hpp"

namespace quadcosim::app {

namespace fs = std::filesystem;

namespace {

// Console summary: pass count, then per figure the runs that have it and the missing ones, and the
// statistics of those that have it.
void print_summary(const nlohmann::json& j, std::ostream& os) {
  const int runs = j["runs"].get<int>();
  const int passed = j["passed"].get<int>();
  os << fmt::format("sweep {}: {} of {} runs passed ({:.1f} %), seed {}\n", j["scenario"].get<std::string>(), passed,
                    runs, 100.0 * passed / runs, j["seed"].get<std::uint64_t>());
  int failed_runs = 0;
  for (const auto& r : j["per_run"]) failed_runs += r.contains("error") ? 1 : 0;
  if (failed_runs > 0)
    os << fmt::format("  {} runs could not be flown (their error is in summary.json)\n", failed_runs);
  os << fmt::format("  {:<36} {:>6} {:>7}  {:>10} {:>10} {:>10} {:>10} {:>10} {:>10}\n", "figure", "count", "missing",
                    "mean", "std", "min", "p50", "p95", "max");
  for (const auto& [name, d] : j["figures"].items()) {
    const auto count = d["count"].get<int>(), missing = d["missing"].get<int>();
    if (count == 0) {
      os << fmt::format("  {:<36} {:>6} {:>7}  (no run has this figure)\n", name, count, missing);
      continue;
    }
    os << fmt::format("  {:<36} {:>6} {:>7}  {:>10.4g} {:>10.4g} {:>10.4g} {:>10.4g} {:>10.4g} {:>10.4g}\n", name,
                      count, missing, d["mean"].get<double>(), d["std"].get<double>(), d["min"].get<double>(),
                      d["p50"].get<double>(), d["p95"].get<double>(), d["max"].get<double>());
  }
}

int verdict(const nlohmann::json& j, double min_pass_rate) {
  return j["passed"].get<int>() >= sweep::passes_needed(min_pass_rate, j["runs"].get<int>()) ? exit_code::kOk
                                                                                             : exit_code::kFailed;
}

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

int rerun_command(const SweepOptions& o) {
  sweep::Plan plan;
  try {
    plan = sweep::plan_of(o.sweep_dir);
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
    fs::copy_file(fs::path(o.sweep_dir) / "scenario.yaml", out / "scenario.yaml", fs::copy_options::overwrite_existing);
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
  fs::copy_file(fs::path(o.shard_dirs.front()) / "scenario.yaml", out / "scenario.yaml",
                fs::copy_options::overwrite_existing);
  sweep::write_json(out / "summary.json", summary);  // a write failure: exit 3 naming the file (run_guarded)
  print_summary(summary, std::cout);
  std::cout << "wrote " << (out / "summary.json").string() << " from " << o.shard_dirs.size() << " shards\n";
  if (o.plots && !run_tool("plot_sweep.py", {o.out_dir})) return exit_code::kOutput;
  return verdict(summary, o.min_pass_rate);
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
  c->add_option("--out", o.out_dir, "output directory: new or empty (created when missing)");
  c->add_option("--jobs", o.jobs, "parallel runs (threads)")->check(CLI::Range(1, 64));
  c->add_option("--min-pass-rate", o.min_pass_rate, "exit 1 when fewer runs than this fraction pass")
      ->check(CLI::Range(0.0, 1.0));
  c->add_flag("!--no-plots", o.plots, "skip the plots");

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
  m->add_flag("!--no-plots", o.plots, "skip the plots");
  m->callback([&o] { o.mode = "merge"; });
  return c;
}

int sweep_command(const SweepOptions& o) {
  if (o.mode == "rerun") return rerun_command(o);
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
  const sweep::Plan plan = sweep::make_plan(o.scenario, o.vary, o.seed, grid && !o.runs_given ? 1 : o.runs,
                                            o.sampler == "lhs" ? sweep::Sampler::kLhs : sweep::Sampler::kRandom);
  if (plan.nominal.steps.empty() && !plan.nominal.hold && !plan.nominal.tracking) {
    std::cerr << "error: " << o.scenario << ": analysis: the scenario has no steps, no hold criterion and no "
              << "trajectory to track; a sweep needs something to judge\n";
    return exit_code::kBadInput;
  }
  const fs::path out(o.out_dir);
  io::OutputFolder folder = io::OutputFolder::claim(out, "sweep", {.force = o.force}, std::cerr);
  fs::create_directories(out / "runs");
  fs::copy_file(o.scenario, out / "scenario.yaml", fs::copy_options::overwrite_existing);
  const sweep::Keep keep = o.keep == "all"       ? sweep::Keep::kAll
                           : o.keep == "failing" ? sweep::Keep::kFailing
                                                 : sweep::Keep::kNone;
  const std::vector<int> indices = sweep::shard_indices(plan.runs, shard, shards);
  const auto results = sweep::run_many(plan, indices, o.jobs, out / "runs", keep);

  std::vector<nlohmann::json> per_run;
  per_run.reserve(results.size());
  for (const auto& r : results) {
    if (!r.error.empty()) {
      std::cerr << fmt::format("sweep: run {} (seed {}) failed: {}\n", r.sample.index, r.sample.seed, r.error);
    }
    per_run.push_back(sweep::per_run_json(plan, r));
  }
  const nlohmann::json header = sweep::header_json(plan);
  if (!o.shard.empty()) {
    int passed = 0;
    for (const auto& r : results) passed += r.passed ? 1 : 0;
    nlohmann::json j = {{"header", header}, {"shard", o.shard}, {"per_run", per_run}};
    sweep::write_json(out / "shard.json", j);
    std::cout << fmt::format(
        "sweep {} shard {}: {} of {} runs ({} passed); wrote {} and runs/NNNN/metrics.json; "
        "join the shards with `quadcosim sweep merge OUT DIR...`\n",
        plan.nominal.name, o.shard, results.size(), plan.runs, passed, (out / "shard.json").string());
    return exit_code::kOk;
  }
  const nlohmann::json summary = sweep::summary_json(header, std::move(per_run));
  sweep::write_json(out / "summary.json", summary);  // a write failure: exit 3 naming the file (run_guarded)
  print_summary(summary, std::cout);
  std::cout << "wrote " << (out / "summary.json").string() << " and runs/NNNN/metrics.json\n";
  if (o.plots && !run_tool("plot_sweep.py", {o.out_dir})) return exit_code::kOutput;
  return verdict(summary, o.min_pass_rate);
}

}  // namespace quadcosim::app
