// The runs of `quadcosim sweep` (docs/sweeps.md) and what is said of them: the runs of a shard that
// a sweep folder does not hold yet, flown with a progress line, the manifest kept current and Ctrl-C
// finishing the runs under way; the summary table and the verdict of a summary.json. Drawing, running
// and summarising one run is the sweep library's (src/sweep/); the flags and the folder's files
// (scenario, origin, summary) are the front end's.
#pragma once

#include <cstddef>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <ostream>
#include <vector>

#include "io/output_folder.hpp"
#include "sweep/sweep.hpp"

namespace quadcosim::hosts {

struct SweepRunsOptions {
  int jobs = 2;                           ///< threads
  sweep::Keep keep = sweep::Keep::kNone;  ///< whose trajectories are kept
  bool resume = false;                    ///< say how many runs were finished before and how many are left
  bool progress = true;                   ///< the progress line on stderr (hosts/sweep_progress.hpp)
  double progress_every_s = 5.0;          ///< seconds between progress lines when stderr is no terminal
};

struct SweepRunsDone {
  std::size_t expected = 0;  ///< runs of the shard: those finished before and those flown now
  bool interrupted = false;  ///< Ctrl-C or SIGTERM stopped it before every run was flown
};

/// Flies the runs of shard `shard` of `shards` of `plan` that `per_run` (the runs finished before,
/// --resume) does not hold into `out`/runs/, appends their per-run JSON and sorts `per_run` by index.
/// Ctrl-C or SIGTERM: no new run starts, those under way finish. The manifest of `folder` is recorded
/// at most once a second while the runs go. A run that failed is said on `errors`.
SweepRunsDone fly_sweep_runs(const sweep::Plan& plan, int shard, int shards, const std::filesystem::path& out,
                             const SweepRunsOptions& o, io::OutputFolder& folder, std::vector<nlohmann::json>& per_run,
                             std::ostream& text, std::ostream& errors);

/// The summary (summary.json) as the console table: the pass count, then per figure the runs that have
/// it, the missing ones and the statistics of those that have it.
void print_sweep_summary(const nlohmann::json& summary, std::ostream& os);

/// The sweep's exit code: a run whose controller failed makes it exit as `run` would (5, said on
/// `errors`); otherwise 0 or 1 by the pass rate against `min_pass_rate`.
int sweep_verdict(const nlohmann::json& summary, double min_pass_rate, std::ostream& errors);

}  // namespace quadcosim::hosts
