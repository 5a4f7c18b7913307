// Step figures of a run checked against the scenario's criteria, written as metrics.json and as a
// readable table.
#pragma once

#include <map>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

#include "analysis/step_metrics.hpp"
#include "io/scenario.hpp"

namespace quadcosim::io {

/// Recorded signals of a run: time and, per channel (x, y, z, roll, pitch, yaw), the measured value
/// and its setpoint ("z" and "z_des"); from a trajectory.csv also, when it has them, the saturation
/// flags "sat1".."sat4", "tilt_sat" (0/1) and the collective thrust "U1".
struct Series {
  std::vector<double> t_s;
  std::map<std::string, std::vector<double>> values;
  void append(const std::string& name, double v) { values[name].push_back(v); }
};

struct CriterionResult {
  Criterion criterion;
  std::optional<double> value;
  bool passed = false;
  /// Why it failed whatever its bounds (e.g. "the run ended before settling: ..."), else "".
  std::string note;
};

struct StepResult {
  StepSpec spec;
  analysis::StepFigures figures;
  std::vector<CriterionResult> criteria;
  bool passed = true;
};

/// The position-hold figures (HoldSpec) of a run and their verdicts.
struct HoldResult {
  HoldSpec spec;
  std::map<std::string, double> figures;  ///< by hold_figure_names(); absent when no sample follows after_s
  std::vector<CriterionResult> criteria;
  bool passed = true;
};

/// The tracking figures of a run (analysis::tracking_figures over t >= spec.after_s) and their verdicts.
struct TrackingResult {
  TrackingSpec spec;
  std::size_t samples = 0;                ///< samples the position figures count
  std::map<std::string, double> figures;  ///< by analysis::tracking_figure_names(); absent when not computable
  std::vector<CriterionResult> criteria;
  bool passed = true;
};

/// What a run did against its motor and tilt limits (docs/outputs.md, "Saturation"), and the
/// verdicts of the scenario's analysis.limits.
struct SaturationResult {
  std::map<std::string, double> figures;  ///< by saturation_figure_names(); rms_u1_deviation_n absent without U1
  std::vector<CriterionResult> criteria;
  bool passed = true;
  double saturated_s() const { return figures.at("saturated_s"); }
  double tilt_saturated_s() const { return figures.at("tilt_saturated_s"); }
  double rotor_saturated_s(int rotor) const { return figures.at(fmt_rotor(rotor)); }  ///< rotor 1..4
  static std::string fmt_rotor(int rotor) { return "rotor" + std::to_string(rotor) + "_saturated_s"; }
};

/// "saturated_s", "rotor1_saturated_s" .. "rotor4_saturated_s", "tilt_saturated_s", "rms_u1_deviation_n".
const std::vector<std::string>& saturation_figure_names();

/// The columns a Series holds besides t, in this order: the judged channels and their setpoints (x .. yaw,
/// x_des .. yaw_des), then the saturation flags sat1..sat4, tilt_sat, U1 and the attitude error att_err
/// (absent from a trajectory.csv written before they existed).
const std::vector<std::string>& series_columns();

/// The series of a trajectory.csv (columns t, x, y, z, roll, pitch, yaw and their *_des; the
/// saturation columns, U1 and att_err when present). Throws std::runtime_error naming the file and the
/// missing column or bad line.
Series read_series(const std::string& trajectory_csv);

/// Evaluates every step of the scenario. The target is the channel's setpoint at the step time;
/// roll, pitch and yaw are judged as angles (shortest-path step, unwrapped response). A step is
/// judged from its instant to the next later step of the same channel, or to the end of the run.
std::vector<StepResult> evaluate_steps(const std::vector<StepSpec>& steps, const Series& series);

/// The saturation figures of a run and the verdicts of `scenario.limits`; empty when the series has
/// no saturation columns (a trajectory.csv written before they existed).
std::optional<SaturationResult> evaluate_saturation(const Scenario& scenario, const Series& series);

/// One line for the console when the run hit a limit ("run: warning: rotor saturation: ..."), or "".
std::string saturation_warning(const SaturationResult& saturation);

bool all_passed(const std::vector<StepResult>& results);

/// The verdict of a run (metrics.json "passed", the exit code of `run`, a sweep run's "passed"):
/// every step passed, and the hold, the saturation limits and the tracking when judged.
bool passed_overall(const std::vector<StepResult>& results, const std::optional<HoldResult>& hold,
                    const std::optional<SaturationResult>& saturation,
                    const std::optional<TrackingResult>& tracking = {});

/// Evaluates the hold criterion over the samples with t >= spec.after_s.
HoldResult evaluate_hold(const HoldSpec& spec, const Series& series);

/// Evaluates the tracking figures and criteria over the samples with t >= spec.after_s: reference the
/// x_des, y_des, z_des, yaw_des columns, measured x, y, z, yaw, Psi the att_err column when present. A
/// criterion on a figure that is absent fails, with a note saying why.
TrackingResult evaluate_tracking(const TrackingSpec& spec, const Series& series);

/// The content of metrics.json (schema in docs/outputs.md), for callers that add to it (a sweep adds
/// the run's seed and varied values).
nlohmann::json metrics_json(const Scenario& scenario, const std::vector<StepResult>& results,
                            const std::optional<HoldResult>& hold = {},
                            const std::optional<SaturationResult>& saturation = {},
                            const std::optional<TrackingResult>& tracking = {});

/// Writes metrics.json (schema in docs/outputs.md). Throws std::runtime_error on I/O failure.
/// `hold`, `saturation` and `tracking`, when given, are written under their names and count in "passed".
void write_metrics_json(const std::string& path, const Scenario& scenario, const std::vector<StepResult>& results,
                        const std::optional<HoldResult>& hold = {},
                        const std::optional<SaturationResult>& saturation = {},
                        const std::optional<TrackingResult>& tracking = {});

/// A fixed-width table: one line per figure with value, criterion, verdict and reference; a figure
/// that could not be judged shows why under its line.
std::string format_step_table(const Scenario& scenario, const std::vector<StepResult>& results,
                              const std::optional<HoldResult>& hold = {},
                              const std::optional<SaturationResult>& saturation = {},
                              const std::optional<TrackingResult>& tracking = {});

}  // namespace quadcosim::io
