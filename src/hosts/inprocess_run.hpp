// The in-process part of `quadcosim run` as library functions, so that every front end that runs a
// scenario in one process (the CLI, the Python module) records and judges it with the same code and
// writes the same bytes.
#pragma once

#include <filesystem>
#include <functional>
#include <nlohmann/json.hpp>
#include <optional>
#include <ostream>
#include <string>
#include <vector>

#include "hosts/node_options.hpp"
#include "io/scenario.hpp"
#include "io/step_report.hpp"

namespace quadcosim::hosts {

/// Flies `scenario` in one process (sim::Simulation) and records it into `out`: trajectory.csv,
/// run.mcap and metadata.yaml. Notes on the plant's watchdog go to `warn` as they happen; the run's
/// watchdog, injected-fault and command-rejection counts to `info` at the end. `on_tick`, when set, is
/// called with each recorded tick's time [s]; when it returns true the run stops there (what ran stays
/// recorded: the CSV flushed, the MCAP file finished) and fly_inprocess returns false. `on_end`, when set,
/// is called after the last tick of a completed run, before the recordings finish and the counts are written.
/// `foxglove`: with `listen` set, the run's topics are also served live (one more recorder: hosts/recording.hpp; it
/// waits for a client, paces and lingers as asked). Throws std::invalid_argument when the controller refuses a
/// scheduled parameter, std::runtime_error on I/O (io::ConfigError for a bad --foxglove).
bool fly_inprocess(const io::Scenario& scenario, const std::filesystem::path& out, std::ostream& info,
                   std::ostream& warn, const std::function<bool(double t_s)>& on_tick = {},
                   const std::function<void()>& on_end = {}, const FoxgloveOptions& foxglove = {});

/// A run's figures and verdicts, judged from its recorded trajectory.csv.
struct RunJudgement {
  io::Judge judge = io::Judge::kSpec;  ///< the criteria set judged (--judge)
  std::vector<io::StepResult> steps;
  std::optional<io::HoldResult> hold;
  std::optional<io::SaturationResult> saturation;
  std::optional<io::TrackingResult> tracking;
  std::string table;         ///< metrics.txt
  std::string nothing_note;  ///< "no paper bands in this scenario: nothing judged" or "" (io::nothing_judged_note)
  /// No judged criterion failed: the exit code of `run` is 1 exactly when this is false. True under
  /// Judge::kNone and when the scenario has none of the judged set (metrics.json's "passed" is then
  /// null, or true with "judged_criteria": 0).
  bool passed = false;
};

/// Judges `out`/trajectory.csv (the exact doubles recorded) against the scenario's steps, hold, limits
/// and tracking, on the criteria of the set `judge` names (every figure and band is written whatever
/// the set), and writes `out`/metrics.json (with `provenance`, the run's io::describe_run record,
/// under "provenance" when it is not null) and `out`/metrics.txt. Throws std::runtime_error on I/O.
RunJudgement judge_run(const io::Scenario& scenario, const std::filesystem::path& out,
                       io::Judge judge = io::Judge::kSpec, const nlohmann::json& provenance = nullptr);

}  // namespace quadcosim::hosts
