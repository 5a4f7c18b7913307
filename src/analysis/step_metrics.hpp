// Step-response figures of a sampled signal, as control engineers quote them.
#pragma once

#include <optional>
#include <span>
#include <string>
#include <vector>

namespace quadcosim::analysis {

/// Figures of a step from y0 (the measured value at the step) to `target`. Times are measured from
/// the step instant [s]. A figure is empty when the response never reaches the level it needs.
struct StepFigures {
  double initial = 0.0;  ///< y at the step
  double target = 0.0;   ///< setpoint after the step
  std::optional<double> overshoot_pct;       ///< (peak - target) / (target - y0) * 100, >= 0
  std::optional<double> peak_time_s;         ///< time of the extreme beyond the target (if any)
  std::optional<double> rise_time_s;         ///< 10 % -> 90 % of the step
  std::optional<double> t95_s;               ///< first time 95 % of the step is reached
  std::optional<double> settling_time_2pct_s;  ///< from then on within 2 % of the step size
  std::optional<double> steady_state_error_pct;  ///< |mean(y over the final window) - target| / |step|
};

struct StepOptions {
  double settling_band = 0.02;       ///< fraction of the step size
  double final_window_s = 1.0;       ///< averaging window for the steady-state error [s]
};

/// t and y sampled together (t increasing). Samples before t_step are ignored. Returns empty figures
/// when fewer than two samples follow the step or the step size is zero.
StepFigures step_figures(std::span<const double> t_s, std::span<const double> y, double t_step_s,
                         double target, const StepOptions& options = {});

/// Names used in files and criteria: "overshoot_pct", "peak_time_s", "rise_time_s", "t95_s",
/// "settling_time_2pct_s", "steady_state_error_pct".
const std::vector<std::string>& figure_names();

/// The figure called `name`, or empty (also for an unknown name).
std::optional<double> figure(const StepFigures& f, const std::string& name);

}  // namespace quadcosim::analysis
