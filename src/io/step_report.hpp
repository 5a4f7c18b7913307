// Step figures of a run checked against the scenario's criteria, written as metrics.json and as a
// readable table.
#pragma once

#include <map>
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

/// The series of a trajectory.csv (columns t, x, y, z, roll, pitch, yaw and their *_des). Throws
/// std::runtime_error naming the file and the missing column or bad line.
Series read_series(const std::string& trajectory_csv);

/// Evaluates every step of the scenario. The target is the channel's setpoint at the step time.
std::vector<StepResult> evaluate_steps(const std::vector<StepSpec>& steps, const Series& series);

bool all_passed(const std::vector<StepResult>& results);

/// Writes metrics.json (schema in docs/outputs.md). Throws std::runtime_error on I/O failure.
void write_metrics_json(const std::string& path, const Scenario& scenario,
                        const std::vector<StepResult>& results);

/// A fixed-width table: one line per figure with value, criterion, verdict and reference.
std::string format_step_table(const Scenario& scenario, const std::vector<StepResult>& results);

}  // namespace quadcosim::io
