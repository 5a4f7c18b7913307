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
/// and its setpoint ("z" and "z_des").
struct Series {
  std::vector<double> t_s;
  std::map<std::string, std::vector<double>> values;
  void append(const std::string& name, double v) { values[name].push_back(v); }
};

struct CriterionResult {
  Criterion criterion;
  std::optional<double> value;
  bool passed = false;
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

/// The series of a trajectory.csv (columns t, x, y, z, roll, pitch, yaw and their *_des). Throws
/// std::runtime_error naming the file and the missing column or bad line.
Series read_series(const std::string& trajectory_csv);

/// Evaluates every step of the scenario. The target is the channel's setpoint at the step time.
std::vector<StepResult> evaluate_steps(const std::vector<StepSpec>& steps, const Series& series);

bool all_passed(const std::vector<StepResult>& results);

/// Evaluates the hold criterion over the samples with t >= spec.after_s.
HoldResult evaluate_hold(const HoldSpec& spec, const Series& series);

/// The content of metrics.json (schema in docs/outputs.md), for callers that add to it (a sweep adds
/// the run's seed and varied values).
nlohmann::json metrics_json(const Scenario& scenario, const std::vector<StepResult>& results,
                            const std::optional<HoldResult>& hold = {});

/// Writes metrics.json (schema in docs/outputs.md). Throws std::runtime_error on I/O failure.
/// `hold`, when given, is written under "hold" and counts in "passed".
void write_metrics_json(const std::string& path, const Scenario& scenario,
                        const std::vector<StepResult>& results, const std::optional<HoldResult>& hold = {});

/// A fixed-width table: one line per figure with value, criterion, verdict and reference.
std::string format_step_table(const Scenario& scenario, const std::vector<StepResult>& results,
                              const std::optional<HoldResult>& hold = {});

}  // namespace quadcosim::io
