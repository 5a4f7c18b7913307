// A run's figures checked against the scenario's criteria (docs/scenarios.md, "Criteria"): the step
// figures, the position hold, the saturation limits and the tracking, each criterion of both sets
// checked against its band, and the verdicts of the set --judge names. Written out by step_report.hpp.
#pragma once

#include <algorithm>
#include <cstddef>
#include <map>
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

/// One criterion checked: whether the value lies in its band (`passed`, computed for both sets) and
/// whether the run is judged on it (its set is the one --judge names).
struct CriterionResult {
  Criterion criterion;
  std::optional<double> value;
  bool passed = false;  ///< the value lies in the band
  bool judged = false;  ///< the band's set is the judged one: outside it the run fails
  /// Why it failed whatever its bounds (e.g. "the run ended before settling: ..."), else "".
  std::string note;
};

struct StepResult {
  StepSpec spec;
  analysis::StepFigures figures;
  std::vector<CriterionResult> criteria;
  bool passed = true;  ///< every judged criterion passed (true when none is judged)
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
  double rotor_saturated_s(int rotor) const { return figures.at(fmt_rotor(rotor)); }  ///< rotor 1..N
  int rotors = 4;  ///< N: the rotors with a figure rotor<k>_saturated_s
  static std::string fmt_rotor(int rotor) { return "rotor" + std::to_string(rotor) + "_saturated_s"; }
};

/// "saturated_s", "rotor1_saturated_s" .. "rotor4_saturated_s" (.. "rotor8_saturated_s" for a vehicle with
/// more rotors: figures only its rotors have), "tilt_saturated_s" (as the controller
/// reports them), "rms_u1_deviation_n", then "command_at_limit_s": how long some rotor's command acting
/// at the plant was at or beyond the vehicle's speed limits, measured by quadcosim whatever the
/// controller reports (absent for a trajectory without the cmd columns).
const std::vector<std::string>& saturation_figure_names();
/// The same for a vehicle with `rotors` rotors: rotor5_saturated_s .. after rotor4_saturated_s.
std::vector<std::string> saturation_figure_names(int rotors);

/// The columns a Series holds besides t, in this order: the judged channels and their setpoints (x .. yaw,
/// x_des .. yaw_des), then the saturation flags sat1..sat4, tilt_sat, U1, the attitude error att_err and
/// the rotor commands acting at the plant cmd1..cmd4 (absent from a trajectory.csv written before they
/// existed), safety, watchdog, vz; then, for a vehicle with more than four rotors only, sat5..sat8 and
/// cmd5..cmd8 (those of its rotors).
const std::vector<std::string>& series_columns();
/// How many of series_columns() every Series of a four-rotor vehicle holds (up to vz).
inline constexpr std::size_t kSeriesColumnsOfFourRotors = 26;

/// Whether `channel` is judged as an angle (roll, pitch, yaw: shortest-path steps, unwrapped response).
bool is_angle_channel(const std::string& channel);

/// How many of a block's criteria are judged (of the set --judge names).
template <class Result>
std::size_t count_judged(const Result& r) {
  return static_cast<std::size_t>(
      std::count_if(r.criteria.begin(), r.criteria.end(), [](const CriterionResult& c) { return c.judged; }));
}

/// Evaluates every step of the scenario. The target is the channel's setpoint at the step time;
/// roll, pitch and yaw are judged as angles (shortest-path step, unwrapped response). A step is
/// judged from its instant to the next later step of the same channel, or to the end of the run.
/// Every criterion of both sets is checked against its band; the results' verdicts count only the
/// criteria of the set `judge` names (none under Judge::kNone). The same holds for every evaluate_*.
std::vector<StepResult> evaluate_steps(const std::vector<StepSpec>& steps, const Series& series,
                                       Judge judge = Judge::kSpec);

/// The saturation figures of a run and the verdicts of `scenario.limits`; empty when the series has
/// no saturation columns (a trajectory.csv written before they existed).
std::optional<SaturationResult> evaluate_saturation(const Scenario& scenario, const Series& series,
                                                    Judge judge = Judge::kSpec);

/// One line for the console when the run hit a limit ("run: warning: rotor saturation: ..."), or "".
std::string saturation_warning(const SaturationResult& saturation);

bool all_passed(const std::vector<StepResult>& results);

/// The verdict of a run (metrics.json "passed", the exit code of `run`, a sweep run's "passed"):
/// every step passed, and the hold, the saturation limits and the tracking when judged. True when no
/// criterion is judged (--judge none, or a scenario without the judged set): metrics.json then says so.
bool passed_overall(const std::vector<StepResult>& results, const std::optional<HoldResult>& hold,
                    const std::optional<SaturationResult>& saturation,
                    const std::optional<TrackingResult>& tracking = {});

/// How many criteria the results judged (of the set --judge names).
std::size_t judged_criteria(const std::vector<StepResult>& results, const std::optional<HoldResult>& hold,
                            const std::optional<SaturationResult>& saturation,
                            const std::optional<TrackingResult>& tracking);

/// What `judge` judges against, for the table and the console: "spec (the specification: bounds a good
/// controller must meet)", "paper (the paper's controller's measured response bands)", "none (...)".
std::string judged_set_text(Judge judge);

/// "no paper bands in this scenario: nothing judged" (or "no spec criteria ...") when the scenario has
/// no criterion of the set `judge` names; "" otherwise and under Judge::kNone.
std::string nothing_judged_note(const Scenario& scenario, Judge judge);

/// Evaluates the hold criterion over the samples with t >= spec.after_s.
HoldResult evaluate_hold(const HoldSpec& spec, const Series& series, Judge judge = Judge::kSpec);

/// Evaluates the tracking figures and criteria over the samples with t >= spec.after_s: reference the
/// x_des, y_des, z_des, yaw_des columns, measured x, y, z, yaw, Psi the att_err column when present. A
/// criterion on a figure that is absent fails, with a note saying why.
TrackingResult evaluate_tracking(const TrackingSpec& spec, const Series& series, Judge judge = Judge::kSpec);

}  // namespace quadcosim::io
