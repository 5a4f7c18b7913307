// Step-response figures of a sampled signal, as control engineers quote them. Every figure's exact
// definition is in docs/outputs.md ("How each step figure is found").
#pragma once

#include <optional>
#include <span>
#include <string>
#include <vector>

namespace quadcosim::analysis {

/// Whether a step could be judged to its end.
enum class StepVerdict {
  kSettled,     ///< every sample of the final window is inside the settling band
  kNotSettled,  ///< the run ended outside the band, or the final window is not all inside it
  kTooShort,    ///< the post-step time cannot hold the final window (or fewer than two samples follow)
  kZeroStep,    ///< the step size is zero (|step| <= kZeroStep): no normalised figure exists
};

/// |step| at or below this (in the channel's SI unit: 1 nm, 1 nrad) is a zero-size step.
inline constexpr double kZeroStep = 1e-9;

/// Figures of a step from y0 (the measured value at the step) to `target`. Times are measured from
/// the step instant [s]. A figure is empty when the response never reaches the level it needs, when
/// the run ended before settling (settling time) or when the run was too short to judge.
struct StepFigures {
  double initial = 0.0;  ///< y at the step
  double target = 0.0;   ///< setpoint after the step (as recorded; an angle is not unwrapped)
  double step = 0.0;     ///< the step judged: target - initial, for an angle wrapped to (-pi, pi]
  StepVerdict verdict = StepVerdict::kTooShort;
  double post_step_s = 0.0;                    ///< recorded time from the step to the last sample [s]
  double final_window_s = 0.0;                 ///< length of the final window the verdict and the error were judged on
  std::optional<double> overshoot_pct;         ///< (peak - target) / (target - y0) * 100, >= 0
  std::optional<double> peak_time_s;           ///< time of the extreme beyond the target (if any)
  std::optional<double> rise_time_s;           ///< 10 % -> 90 % of the step
  std::optional<double> t95_s;                 ///< first time 95 % of the step is reached
  std::optional<double> settling_time_2pct_s;  ///< last entry into the band, staying in it to the end
  std::optional<double> steady_state_error_pct;  ///< |mean(y over the final window) - target| / |step|
};

struct StepOptions {
  double settling_band = 0.02;          ///< fraction of the step size
  double final_window_fraction = 0.10;  ///< final window: this share of the post-step time ...
  double final_window_min_s = 1.0;      ///< ... and at least this long [s]
  /// The signal is an angle [rad]: the step is the shortest-path difference (wrapped to (-pi, pi])
  /// and the response is unwrapped (no 2 pi jumps) before it is judged.
  bool angle = false;
};

/// t and y sampled together (t increasing). Samples before t_step are ignored.
StepFigures step_figures(std::span<const double> t_s, std::span<const double> y, double t_step_s, double target,
                         const StepOptions& options = {});

/// `y` with every jump of more than pi between neighbours taken the short way (numpy.unwrap).
std::vector<double> unwrap_angle(std::span<const double> y_rad);

/// Names used in files and criteria: "overshoot_pct", "peak_time_s", "rise_time_s", "t95_s",
/// "settling_time_2pct_s", "steady_state_error_pct".
const std::vector<std::string>& figure_names();

/// The figure called `name`, or empty (also for an unknown name).
std::optional<double> figure(const StepFigures& f, const std::string& name);

/// "settled", "not settled", "too short to judge", "zero-size step".
const char* to_string(StepVerdict verdict);

/// Why a criterion on `name` cannot pass whatever its bounds, or "" when the value decides: a
/// settling or steady-state criterion on a step that is not settled or too short; any criterion on a
/// zero-size step. The text says what happened with the numbers, e.g. "the run ended before
/// settling: not inside the 2 % band over the final 1 s window".
std::string unjudgeable_reason(const StepFigures& f, const std::string& name, const StepOptions& options = {});

}  // namespace quadcosim::analysis
