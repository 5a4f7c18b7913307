// Running a sweep's runs and summarising them (docs/sweeps.md). No console output: callers (the
// CLI, later Python) print what they want from the returned results and JSON.
#pragma once

#include <filesystem>
#include <functional>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

#include "io/step_report.hpp"
#include "sweep/plan.hpp"

namespace quadcosim::sweep {

/// Which runs keep their trajectory.csv in runs/NNNN/.
enum class Keep { kNone, kFailing, kAll };

struct RunResult {
  Sample sample;
  std::vector<io::StepResult> steps;
  std::optional<io::HoldResult> hold;
  std::optional<io::SaturationResult> saturation;  ///< rotor and tilt saturation, analysis.limits
  std::optional<io::TrackingResult> tracking;      ///< analysis.tracking, or figures of a trajectory run
  bool passed = false;
  std::string error;  ///< non-empty when the run could not be done (a refused value, a failed design)
  /// The error is the controller's own failure (its step raised, returned garbage, crashed or hung):
  /// summary.json says "error_cause": "controller" and the sweep exits 5, as `run` does.
  bool controller_failed = false;
  /// The criteria the run failed, read back from its metrics.json (failed_criteria below); empty for
  /// a passing run or one that could not be flown.
  nlohmann::json failed_criteria = nlohmann::json::array();
};

/// The criteria a run's metrics.json (as `run` and a sweep write it) marks failed, in its order (steps,
/// then the other sections): each {"channel", "name", "value", "bound", "side", "min", "max", "note"},
/// "channel" being the figure's group as summary.json names it ("z", "z#2" for a channel's second step,
/// "hold", "saturation", "tracking"), "name" the figure, "bound" the bound the value is outside ("side"
/// "min" or "max"; both null when the figure has no value, "note" then says why). Every other field of
/// a criterion is carried over as it is, so what the criteria layer adds reaches the sweep's summary.
nlohmann::json failed_criteria(const nlohmann::json& metrics);

/// Simulates run `index` in-process and judges it. With `run_dir` non-empty writes its metrics.json
/// there (and trajectory.csv when `keep` asks for it). Never throws for a bad sample: the reason is
/// in RunResult::error.
RunResult run_one(const Plan& plan, int index, const std::filesystem::path& run_dir, Keep keep = Keep::kNone);

/// How run_many may be stopped early and tells of its progress (both optional).
struct RunControl {
  /// Asked before each run is started (from the worker threads): true stops starting runs; the runs
  /// already started are finished (Ctrl-C of a sweep).
  std::function<bool()> stop;
  /// Called after each run is done, its files written (from the worker threads, one call at a time).
  std::function<void(const RunResult&)> finished;
};

/// Runs `indices` on `jobs` threads, each into runs_dir/NNNN (no files when runs_dir is empty);
/// results in the order of `indices`, whatever the scheduling. When `control.stop` stopped it, the
/// results are those of the runs finished (fewer than asked): the runs started (a leading part of
/// `indices`) but those that failed once the stop was asked (the stop cut them short: a controller
/// in a process of its own is killed on Ctrl-C), whose files are removed, so a resume flies them.
std::vector<RunResult> run_many(const Plan& plan, const std::vector<int>& indices, int jobs,
                                const std::filesystem::path& runs_dir, Keep keep = Keep::kNone,
                                const RunControl& control = {});

/// Runs i with i % count == shard - 1 (shard in 1..count), ascending.
std::vector<int> shard_indices(int runs, int shard, int count);

/// Writes `j` to `path` as JSON indented by 2, with a final newline (summary.json, shard.json, a
/// run's metrics.json), atomically (io::write_file_atomically: the old file or the new one, never a
/// part, never through a link). Throws std::runtime_error naming the file when it cannot be written.
void write_json(const std::filesystem::path& path, const nlohmann::json& j);

/// The fewest passing runs out of `runs` that meet a pass rate `rate` (--min-pass-rate, in [0, 1]):
/// ceil(rate × runs), forgiving the rounding of the product (below 1e-12 relative), so that 0.55 of
/// 100 is 55 (0.55 × 100 is 55.000000000000007 in binary). Throws std::invalid_argument for a rate
/// outside [0, 1] (or NaN) or negative runs.
int passes_needed(double rate, int runs);

/// Flies run `index` again into `dir` with the outputs of `quadcosim run` in-process: trajectory.csv,
/// run.mcap, metadata.yaml, metrics.json (with the "sweep" section), metrics.txt; judged from the
/// recorded CSV as `run` is. Throws io::ConfigError / std::invalid_argument for a refused value,
/// std::runtime_error when a file cannot be written.
RunResult rerun(const Plan& plan, int index, const std::filesystem::path& dir);

/// metrics.json of a sweep run: `quadcosim run`'s, plus "sweep": {index, seed, sweep_seed, values,
/// factors, vehicle: designed vs flown}.
nlohmann::json run_metrics_json(const Plan& plan, const io::Scenario& flown, const RunResult& r);

/// A run's figures by their name in summary.json: "<channel>.<figure>" for steps ("roll.overshoot_pct";
/// a second step of the same channel "roll#2.overshoot_pct"), "hold.<figure>", "saturation.<figure>"
/// (every run has them), "tracking.<figure>"; null when the run could not be flown or lacks the figure.
std::vector<std::pair<std::string, std::optional<double>>> figures_of(const RunResult& r, const io::Scenario& sc);

/// A sample's varied values as a JSON object, by key.
nlohmann::json values_json(const Sample& s);

/// What identifies a sweep: scenario, scenario_file, seed, runs, sampler, runs_per_point, vary.
/// Shards of one sweep have equal headers.
nlohmann::json header_json(const Plan& plan);

/// A run's entry of summary.json's per_run: index, seed, passed, values, factors, figures (steps, hold,
/// saturation), error, and for a failed run "failed_criteria" (RunResult::failed_criteria).
nlohmann::json per_run_json(const Plan& plan, const RunResult& r);

/// summary.json from the header and every run's per_run entry (any order; sorted by index here).
/// Throws std::invalid_argument when an index is missing, repeated or out of range.
nlohmann::json summary_json(const nlohmann::json& header, std::vector<nlohmann::json> per_run);

/// summary.json of an interrupted sweep: the runs that finished (any of the sweep's, each once),
/// "passed" among them, "pass_rate" = passed / finished, the figures' statistics over them, and
/// "partial": {"finished": F, "runs": N}. Throws std::invalid_argument for an index repeated or out of
/// range.
nlohmann::json partial_summary_json(const nlohmann::json& header, std::vector<nlohmann::json> per_run);

/// Checks a parsed shard.json for what `sweep merge` reads: "header" an object with "runs" a whole
/// number, "per_run" an array of objects each with "index" (a whole number), "passed" (true or false)
/// and "figures" (an object of numbers or nulls). Throws std::invalid_argument naming the first field
/// missing or of another type and what it holds ("per_run[3].passed: expected true or false, got \"yes\"").
void check_shard_json(const nlohmann::json& shard);

/// The per_run entries of the interrupted sweep in `sweep_dir` (its summary.json, or shard.json for a
/// shard), for `sweep --resume`. Throws std::invalid_argument naming the file and saying what to do
/// when there is none, it is not a sweep's (or is cut short), or its header or shard differ from
/// `header` and `shard` ("" unsharded); sets `complete` when the sweep there had already finished.
std::vector<nlohmann::json> finished_runs(const std::filesystem::path& sweep_dir, const nlohmann::json& header,
                                          const std::string& shard, bool& complete);

/// Where a sweep was started, recorded in its folder (origin.json) so that `--resume` and `sweep rerun`
/// find what the scenario needs from any current directory: the scenario file (its folder holds a
/// Python controller's module, an FMU, a trajectory file named relative to it) and the folders
/// Python imported from (the scenario's folder, the current directory and PYTHONPATH, in the order
/// the loader searches them). Absolute paths, so it depends on the machine: not one of the outputs
/// that are the same bytes wherever the sweep runs.
struct Origin {
  std::string scenario_file;             ///< absolute, normalised
  std::string cwd;                       ///< the current directory the sweep was started in
  std::vector<std::string> python_path;  ///< absolute folders, each once, in search order
};

/// The file name of the record in a sweep's folder.
inline constexpr const char* kOriginFile = "origin.json";

/// The origin of a sweep of `scenario_file` started now, in `cwd`, with PYTHONPATH `python_path_env`
/// (null or "" when unset; relative entries are taken from `cwd`, empty ones are `cwd` itself).
Origin origin_of(const std::string& scenario_file, const std::filesystem::path& cwd, const char* python_path_env);

nlohmann::json origin_json(const Origin& origin);

/// `sweep_dir`/origin.json, or nullopt when there is none (a sweep of an older quadcosim). Throws
/// io::ConfigError naming the file when it is not an origin record.
std::optional<Origin> read_origin(const std::filesystem::path& sweep_dir);

/// PYTHONPATH for continuing a sweep: the recorded folders first (the modules the sweep imported are
/// imported again), then the entries of `current` (null or "" when unset) not among them.
std::string python_path_env(const Origin& origin, const char* current);

/// The path a continued sweep loads its scenario as (Plan::scenario_source): the recorded scenario
/// file while its folder exists, else "" (the caller's own path is all there is).
std::string scenario_source_of(const Origin& origin);

/// The plan of a sweep directory (its summary.json or shard.json and the scenario.yaml copied into it),
/// loaded as if at the scenario file origin.json records (scenario_source_of). Throws
/// std::runtime_error naming the file.
Plan plan_of(const std::filesystem::path& sweep_dir, const io::ScenarioResolvers& resolvers);

}  // namespace quadcosim::sweep
