// A run's figures and verdicts (io/judging.hpp) written as metrics.json and as a readable table, and
// the recorded series they are computed from read back from a trajectory.csv.
#pragma once

#include <map>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

#include "io/judging.hpp"
#include "io/scenario.hpp"

namespace quadcosim::io {

/// The series of a trajectory.csv (columns t, x, y, z, roll, pitch, yaw and their *_des; the
/// saturation columns, U1 and att_err when present). Throws std::runtime_error naming the file and the
/// missing column or bad line.
Series read_series(const std::string& trajectory_csv);

/// The content of metrics.json (schema in docs/outputs.md), for callers that add to it (a sweep adds
/// the run's seed and varied values). `judge` is the set the results were evaluated with: written as
/// "judged", with "judged_criteria"; every "passed" verdict is null under Judge::kNone.
nlohmann::json metrics_json(const Scenario& scenario, const std::vector<StepResult>& results,
                            const std::optional<HoldResult>& hold = {},
                            const std::optional<SaturationResult>& saturation = {},
                            const std::optional<TrackingResult>& tracking = {}, Judge judge = Judge::kSpec);

/// Writes metrics.json (schema in docs/outputs.md). Throws std::runtime_error on I/O failure.
/// `hold`, `saturation` and `tracking`, when given, are written under their names and count in "passed".
void write_metrics_json(const std::string& path, const Scenario& scenario, const std::vector<StepResult>& results,
                        const std::optional<HoldResult>& hold = {},
                        const std::optional<SaturationResult>& saturation = {},
                        const std::optional<TrackingResult>& tracking = {}, Judge judge = Judge::kSpec);

/// A fixed-width table: the set judged against, then one line per figure with its value, its spec band
/// and check, its paper band and check (ok/FAIL for the judged set, in/out for the other) and the
/// reference; a figure that could not be judged shows why under its line.
std::string format_step_table(const Scenario& scenario, const std::vector<StepResult>& results,
                              const std::optional<HoldResult>& hold = {},
                              const std::optional<SaturationResult>& saturation = {},
                              const std::optional<TrackingResult>& tracking = {}, Judge judge = Judge::kSpec);

}  // namespace quadcosim::io
