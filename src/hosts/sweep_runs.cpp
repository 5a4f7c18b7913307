// hosts/sweep_runs.hpp: a sweep's runs flown with their progress, and its summary said.
#include "hosts/sweep_runs.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <chrono>
#include <optional>
#include <set>
#include <string>

#include "hosts/exit_code.hpp"
#include "hosts/signals.hpp"
#include "hosts/sweep_progress.hpp"

namespace quadcosim::hosts {

SweepRunsDone fly_sweep_runs(const sweep::Plan& plan, int shard, int shards, const std::filesystem::path& out,
                             const SweepRunsOptions& o, io::OutputFolder& folder, std::vector<nlohmann::json>& per_run,
                             std::ostream& text, std::ostream& errors) {
  std::filesystem::create_directories(out / "runs");
  std::set<int> done;
  for (const auto& r : per_run) done.insert(r.at("index").get<int>());
  std::vector<int> indices;
  for (const int i : sweep::shard_indices(plan.runs, shard, shards)) {
    if (done.count(i) == 0) indices.push_back(i);
  }
  if (o.resume) {
    text << fmt::format("sweep {}: resuming in {}: {} runs finished, {} to run\n", plan.nominal.name, out.string(),
                        done.size(), indices.size());
  }
  // Ctrl-C or SIGTERM: no new run starts, those under way finish, and the summary of the finished ones
  // is written. Meanwhile the manifest lists what is written, at most a second late.
  install_stop_handlers();
  auto last_record = std::chrono::steady_clock::now();
  int passed_before = 0;
  for (const auto& r : per_run) passed_before += r.at("passed").get<bool>() ? 1 : 0;
  std::optional<SweepProgress> progress;
  if (o.progress && !indices.empty()) {
    progress.emplace(plan.nominal.name, static_cast<int>(done.size() + indices.size()), static_cast<int>(done.size()),
                     passed_before, o.progress_every_s);
  }
  sweep::RunControl control;
  control.stop = [] { return stop_requested(); };
  control.finished = [&](const sweep::RunResult& r) {
    if (progress) progress->finished(r.passed);
    const auto now = std::chrono::steady_clock::now();
    if (now - last_record < std::chrono::seconds(1)) return;
    last_record = now;
    try {
      folder.record("outputs");
    } catch (const std::exception&) {
      // A full disk, say: the manifest stays the last one written; the run's own write reports it.
    }
  };
  const auto results = sweep::run_many(plan, indices, o.jobs, out / "runs", o.keep, control);
  if (progress) progress->end();
  for (const auto& r : results) {
    if (!r.error.empty()) {
      errors << fmt::format("sweep: run {} (seed {}) failed: {}\n", r.sample.index, r.sample.seed, r.error);
    }
    per_run.push_back(sweep::per_run_json(plan, r));
  }
  std::sort(per_run.begin(), per_run.end(), [](const auto& a, const auto& b) {
    return a.at("index").template get<int>() < b.at("index").template get<int>();
  });
  return {done.size() + indices.size(), results.size() < indices.size()};
}

// Console summary: pass count, then per figure the runs that have it and the missing ones, and the
// statistics of those that have it.
void print_sweep_summary(const nlohmann::json& j, std::ostream& os) {
  const int runs = j["runs"].get<int>();
  const int passed = j["passed"].get<int>();
  if (j.contains("partial")) {
    const int finished = j["partial"]["finished"].get<int>();
    os << fmt::format("sweep {}: interrupted: {} of {} runs finished; {} of them passed ({:.1f} %), seed {}\n",
                      j["scenario"].get<std::string>(), finished, runs, passed,
                      finished > 0 ? 100.0 * passed / finished : 0.0, j["seed"].get<std::uint64_t>());
  } else if (j.value("judge", std::string("spec")) == "none") {
    os << fmt::format("sweep {}: {} runs, figures only (--judge none: no verdict), seed {}\n",
                      j["scenario"].get<std::string>(), runs, j["seed"].get<std::uint64_t>());
  } else {
    os << fmt::format("sweep {}: {} of {} runs passed ({:.1f} %) against {}, seed {}\n",
                      j["scenario"].get<std::string>(), passed, runs, 100.0 * passed / runs,
                      j.value("judge", std::string("spec")), j["seed"].get<std::uint64_t>());
  }
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

// A run whose controller failed makes the sweep exit as `run` would (5): the controller needs fixing
// before its pass rate means anything. Otherwise 0 or 1 by the pass rate.
int sweep_verdict(const nlohmann::json& j, double min_pass_rate, std::ostream& errors) {
  int controller_failures = 0;
  for (const nlohmann::json& run : j.value("per_run", nlohmann::json::array())) {
    if (run.value("error_cause", "") == "controller") ++controller_failures;
  }
  if (controller_failures > 0) {
    errors << fmt::format("sweep: the controller failed in {} run{} (their errors are above and in summary.json)\n",
                          controller_failures, controller_failures == 1 ? "" : "s");
    return exit_code::kControllerFailed;
  }
  return j["passed"].get<int>() >= sweep::passes_needed(min_pass_rate, j["runs"].get<int>()) ? exit_code::kOk
                                                                                             : exit_code::kFailed;
}

}  // namespace quadcosim::hosts
