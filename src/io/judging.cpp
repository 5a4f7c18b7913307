// io/judging.hpp: a run's figures checked against the scenario's criteria.
#include "io/judging.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <span>
#include <stdexcept>

#include "analysis/tracking.hpp"

namespace quadcosim::io {

// The criteria sets and what --judge names (declared beside the scenario's criteria, io/scenario.hpp).

const char* to_string(CriteriaSet set) { return set == CriteriaSet::kSpec ? "spec" : "paper"; }

const char* to_string(Judge judge) {
  switch (judge) {
    case Judge::kSpec: return "spec";
    case Judge::kPaper: return "paper";
    case Judge::kNone: return "none";
  }
  return "?";
}

const std::vector<std::string>& judge_names() {
  static const std::vector<std::string> names = {"spec", "paper", "none"};
  return names;
}

std::optional<Judge> parse_judge(const std::string& name) {
  for (Judge j : {Judge::kSpec, Judge::kPaper, Judge::kNone}) {
    if (name == to_string(j)) return j;
  }
  return std::nullopt;
}

bool has_criteria(const Scenario& sc, CriteriaSet set) {
  const auto any = [&](const std::vector<Criterion>& criteria) {
    return std::any_of(criteria.begin(), criteria.end(), [&](const Criterion& c) { return c.set == set; });
  };
  return std::any_of(sc.steps.begin(), sc.steps.end(), [&](const StepSpec& s) { return any(s.criteria); }) ||
         (sc.hold && any(sc.hold->criteria)) || (sc.limits && any(sc.limits->criteria)) ||
         (sc.tracking && any(sc.tracking->criteria));
}

bool is_angle_channel(const std::string& channel) {
  return channel == "roll" || channel == "pitch" || channel == "yaw";
}

namespace {

// A criterion's value against its band; judged when `judge` judges its set (docs/scenarios.md).
CriterionResult judge_criterion(const Criterion& c, const std::optional<double>& value, Judge judge,
                                std::string note = "") {
  CriterionResult cr{c, value, false, judges(judge, c.set), std::move(note)};
  cr.passed =
      cr.note.empty() && cr.value.has_value() && (!c.min || *cr.value >= *c.min) && (!c.max || *cr.value <= *c.max);
  return cr;
}

// Adds `cr` to r.criteria; a judged criterion outside its band fails r.
template <class Result>
void add_criterion(Result& r, const CriterionResult& cr) {
  r.passed = r.passed && (!cr.judged || cr.passed);
  r.criteria.push_back(cr);
}

// Checks each criterion on the figure of r.figures it names, into r.criteria and r.passed; a figure
// that is absent is outside every band, with why(criterion) as the note.
template <class Result, class Why>
void judge_figures(const std::vector<Criterion>& criteria, Result& r, Judge judge, Why why) {
  for (const Criterion& c : criteria) {
    const auto it = r.figures.find(c.figure);
    add_criterion(r, it == r.figures.end() ? judge_criterion(c, std::nullopt, judge, why(c))
                                           : judge_criterion(c, std::optional<double>(it->second), judge));
  }
}
std::string no_note(const Criterion&) { return {}; }
}  // namespace

std::vector<StepResult> evaluate_steps(const std::vector<StepSpec>& steps, const Series& series, Judge judge) {
  std::vector<StepResult> out;
  for (const StepSpec& spec : steps) {
    StepResult r;
    r.spec = spec;
    const auto y = series.values.find(spec.channel);
    const auto sp = series.values.find(spec.channel + "_des");
    if (y == series.values.end() || sp == series.values.end() || series.t_s.empty()) {
      throw std::logic_error("no recorded series for channel " + spec.channel);
    }
    const auto it = std::lower_bound(series.t_s.begin(), series.t_s.end(), spec.t_step_s);
    std::size_t i = std::min<std::size_t>(it - series.t_s.begin(), series.t_s.size() - 1);
    // The setpoint in effect at the step; in real time the controller's first status may arrive a
    // few ticks after it, so take the first recorded value from the step on.
    while (i + 1 < sp->second.size() && !std::isfinite(sp->second[i])) ++i;
    // Judged up to the next later step of the same channel (its samples excluded).
    double end_s = std::numeric_limits<double>::infinity();
    for (const StepSpec& other : steps) {
      if (other.channel == spec.channel && other.t_step_s > spec.t_step_s) end_s = std::min(end_s, other.t_step_s);
    }
    const auto n =
        static_cast<std::size_t>(std::lower_bound(series.t_s.begin(), series.t_s.end(), end_s) - series.t_s.begin());
    analysis::StepOptions options;
    options.angle = is_angle_channel(spec.channel);
    options.settling_band = spec.settling_band;
    r.figures = analysis::step_figures(std::span(series.t_s).first(n), std::span(y->second).first(n), spec.t_step_s,
                                       sp->second[i], options);
    for (const Criterion& c : spec.criteria) {
      add_criterion(r, judge_criterion(c, analysis::figure(r.figures, c.figure), judge,
                                       analysis::unjudgeable_reason(r.figures, c.figure, options)));
    }
    out.push_back(r);
  }
  return out;
}

const std::vector<std::string>& saturation_figure_names() {
  static const std::vector<std::string> names = {"saturated_s",        "rotor1_saturated_s", "rotor2_saturated_s",
                                                 "rotor3_saturated_s", "rotor4_saturated_s", "tilt_saturated_s",
                                                 "rms_u1_deviation_n", "command_at_limit_s"};
  return names;
}

std::vector<std::string> saturation_figure_names(int rotors) {
  std::vector<std::string> names = saturation_figure_names();
  for (int k = rotors; k > 4; --k) names.insert(names.begin() + 5, SaturationResult::fmt_rotor(k));
  return names;
}

std::optional<SaturationResult> evaluate_saturation(const Scenario& sc, const Series& series, Judge judge) {
  const auto& v = series.values;
  for (const char* c : {"sat1", "sat2", "sat3", "sat4", "tilt_sat"}) {
    if (!v.count(c)) return std::nullopt;
  }
  SaturationResult r;
  const std::size_t n = series.t_s.size();
  // Each row stands for the tick period that follows it (the last row for the one before it).
  auto period = [&](std::size_t i) {
    if (n < 2) return 0.0;
    return i + 1 < n ? series.t_s[i + 1] - series.t_s[i] : series.t_s[i] - series.t_s[i - 1];
  };
  // The rotors: sat1..sat4 always, sat5.. for a vehicle with more (present with as many rows as t).
  int rotors = 4;
  while (rotors < model::kMaxRotors) {
    const auto it = v.find("sat" + std::to_string(rotors + 1));
    if (it == v.end() || it->second.size() != n) break;
    ++rotors;
  }
  std::array<double, model::kMaxRotors> rotor{};
  double any = 0.0, tilt = 0.0, sum_du2 = 0.0;
  std::size_t n_u = 0;
  const double hover_n = sc.vehicle.mass_kg * sc.vehicle.gravity_m_s2;
  const auto u1 = v.find("U1");
  // Measured at the plant: the command acting over each tick against the vehicle's limits.
  std::array<const std::vector<double>*, model::kMaxRotors> command{};
  bool all_commands = true;
  for (int k = 0; k < rotors; ++k) {
    const auto it = v.find("cmd" + std::to_string(k + 1));
    command[k] = it == v.end() ? nullptr : &it->second;
    all_commands = all_commands && command[k];
  }
  const auto safety = v.find("safety"), watchdog = v.find("watchdog");
  const bool measured = all_commands && safety != v.end() && watchdog != v.end() && u1 != v.end();
  const model::MotorParams& motor = sc.vehicle.motor;
  // A vehicle at rest on the ground (z = 0 and vz = 0: the ground contact holds it) with every rotor
  // commanded to omega_min has its motors off (a flight stack disarmed before take-off or after
  // landing, a controller waiting to start): no controller pushes against a limit there, so those
  // rows count as no saturation.
  const auto z = v.find("z"), vz = v.find("vz");
  const bool rests_known = all_commands && z != v.end() && vz != v.end();
  const auto motors_off_on_ground = [&](std::size_t i) {
    if (!rests_known || z->second[i] > 0.0 || vz->second[i] != 0.0) return false;
    for (int k = 0; k < rotors; ++k) {
      if ((*command[k])[i] > motor.omega_min_rad_s) return false;
    }
    return true;
  };
  double at_limit = 0.0;
  for (std::size_t i = 0; i < n; ++i) {
    const double dt = period(i);
    const bool off = motors_off_on_ground(i);
    bool some = false;
    for (int k = 0; k < rotors && !off; ++k) {
      if (v.at("sat" + std::to_string(k + 1))[i] != 0.0) {
        rotor[k] += dt;
        some = true;
      }
    }
    if (some) any += dt;
    if (v.at("tilt_sat")[i] != 0.0) tilt += dt;
    // The controller's commands only: not before its first step (no U1 yet), nor the stale-data safety
    // command or the plant watchdog's (they stop the rotors on purpose).
    if (measured && !off && std::isfinite(u1->second[i]) && safety->second[i] == 0.0 && watchdog->second[i] == 0.0) {
      for (int k = 0; k < rotors; ++k) {
        const double w = (*command[k])[i];
        if (w >= motor.omega_max_rad_s || w <= motor.omega_min_rad_s) {
          at_limit += dt;
          break;
        }
      }
    }
    if (u1 != v.end() && std::isfinite(u1->second[i])) {
      sum_du2 += (u1->second[i] - hover_n) * (u1->second[i] - hover_n);
      ++n_u;
    }
  }
  r.figures["saturated_s"] = any;
  r.rotors = rotors;
  for (int k = 0; k < rotors; ++k) r.figures[SaturationResult::fmt_rotor(k + 1)] = rotor[k];
  r.figures["tilt_saturated_s"] = tilt;
  if (n_u > 0) r.figures["rms_u1_deviation_n"] = std::sqrt(sum_du2 / static_cast<double>(n_u));
  if (measured) r.figures["command_at_limit_s"] = at_limit;
  if (sc.limits) judge_figures(sc.limits->criteria, r, judge, no_note);
  return r;
}

std::string saturation_warning(const SaturationResult& s) {
  const auto measured = s.figures.find("command_at_limit_s");
  const double at_limit = measured == s.figures.end() ? 0.0 : measured->second;
  if (s.saturated_s() <= 0.0 && s.tilt_saturated_s() <= 0.0 && at_limit <= 0.0) return "";
  std::string rotors, times;
  std::string numbers;
  for (int k = 1; k <= s.rotors; ++k) {
    if (s.rotor_saturated_s(k) > 0.0) rotors += (rotors.empty() ? "" : ", ") + std::to_string(k);
    times += fmt::format("{}{:.3f}", k == 1 ? "" : "/", s.rotor_saturated_s(k));
    numbers += fmt::format("{}{}", k == 1 ? "" : "/", k);
  }
  std::string line = "warning: rotor saturation: ";
  std::string said;
  if (s.saturated_s() > 0.0) {
    said = fmt::format("rotor{} {} at omega_min/omega_max for {:.3f} s in total (rotors {}: {} s)",
                       rotors.size() > 1 ? "s" : "", rotors, s.saturated_s(), numbers, times);
  } else if (at_limit > 0.0) {
    // The controller reported nothing, but the commands the plant received say otherwise.
    said = fmt::format(
        "a rotor command acting at the plant was at omega_min/omega_max for {:.3f} s (the controller "
        "reports no saturation)",
        at_limit);
  }
  line += said;
  if (s.tilt_saturated_s() > 0.0) {
    line += fmt::format("{}tilt limit acted for {:.3f} s", said.empty() ? "" : "; ", s.tilt_saturated_s());
  }
  return line +
         "; the response is the limits', not the controller's alone (sat1..N, tilt_sat, cmd1..N in trajectory.csv)";
}

bool all_passed(const std::vector<StepResult>& results) {
  return std::all_of(results.begin(), results.end(), [](const auto& r) { return r.passed; });
}

HoldResult evaluate_hold(const HoldSpec& spec, const Series& series, Judge judge) {
  HoldResult r;
  r.spec = spec;
  const auto& v = series.values;
  const std::vector<std::string> need = {"x", "y", "z", "x_des", "y_des", "z_des"};
  for (const auto& n : need) {
    if (!v.count(n)) throw std::logic_error("no recorded series for " + n);
  }
  double max_h = 0.0, sum_h2 = 0.0, max_v = 0.0;
  std::size_t count = 0;
  for (std::size_t i = 0; i < series.t_s.size(); ++i) {
    if (series.t_s[i] < spec.after_s) continue;
    const double dx = v.at("x")[i] - v.at("x_des")[i], dy = v.at("y")[i] - v.at("y_des")[i];
    const double h = std::hypot(dx, dy);
    const double dz = std::abs(v.at("z")[i] - v.at("z_des")[i]);
    if (!std::isfinite(h) || !std::isfinite(dz)) continue;  // no setpoint recorded yet
    max_h = std::max(max_h, h);
    sum_h2 += h * h;
    max_v = std::max(max_v, dz);
    ++count;
  }
  if (count > 0) {
    r.figures["max_horizontal_error_m"] = max_h;
    r.figures["rms_horizontal_error_m"] = std::sqrt(sum_h2 / static_cast<double>(count));
    r.figures["max_vertical_error_m"] = max_v;
  }
  judge_figures(spec.criteria, r, judge, no_note);
  return r;
}

TrackingResult evaluate_tracking(const TrackingSpec& spec, const Series& series, Judge judge) {
  TrackingResult r;
  r.spec = spec;
  const auto& v = series.values;
  auto column = [&](const std::string& name) -> std::span<const double> {
    const auto it = v.find(name);
    if (it == v.end()) throw std::logic_error("no recorded series for " + name);
    return it->second;
  };
  const auto psi = v.find("att_err");
  const analysis::TrackingSeries s{
      series.t_s,        column("x_des"),
      column("y_des"),   column("z_des"),
      column("yaw_des"), column("x"),
      column("y"),       column("z"),
      column("yaw"),     psi == v.end() ? std::span<const double>() : std::span<const double>(psi->second)};
  const analysis::TrackingFigures f = analysis::tracking_figures(s, spec.after_s, spec.reference_period_s);
  r.samples = f.samples;
  r.figures = f.values;
  judge_figures(spec.criteria, r, judge, [&](const Criterion& c) -> std::string {
    if (f.samples == 0) return fmt::format("no sample with a reference at or after t = {:g} s", spec.after_s);
    if (c.figure.rfind("attitude_error", 0) == 0) return "the controller reports no attitude error (att_err is NaN)";
    return "no sample with a finite yaw and yaw_des";
  });
  return r;
}

std::size_t judged_criteria(const std::vector<StepResult>& results, const std::optional<HoldResult>& hold,
                            const std::optional<SaturationResult>& saturation,
                            const std::optional<TrackingResult>& tracking) {
  std::size_t n = 0;
  for (const StepResult& r : results) n += count_judged(r);
  if (hold) n += count_judged(*hold);
  if (saturation) n += count_judged(*saturation);
  if (tracking) n += count_judged(*tracking);
  return n;
}

std::string judged_set_text(Judge judge) {
  switch (judge) {
    case Judge::kSpec: return "spec (the specification: bounds a good controller must meet)";
    case Judge::kPaper: return "paper (the paper's controller's measured response bands)";
    case Judge::kNone: return "none (figures only: no verdict)";
  }
  return "?";
}

std::string nothing_judged_note(const Scenario& scenario, Judge judge) {
  if (judge == Judge::kSpec && !has_criteria(scenario, CriteriaSet::kSpec)) {
    return "no spec criteria in this scenario: nothing judged";
  }
  if (judge == Judge::kPaper && !has_criteria(scenario, CriteriaSet::kPaper)) {
    return "no paper bands in this scenario: nothing judged";
  }
  return "";
}

bool passed_overall(const std::vector<StepResult>& results, const std::optional<HoldResult>& hold,
                    const std::optional<SaturationResult>& saturation, const std::optional<TrackingResult>& tracking) {
  return all_passed(results) && (!hold || hold->passed) && (!saturation || saturation->passed) &&
         (!tracking || tracking->passed);
}

}  // namespace quadcosim::io
