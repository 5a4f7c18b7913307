#include "io/step_report.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdlib>
#include <fstream>
#include <limits>
#include <nlohmann/json.hpp>
#include <span>
#include <sstream>
#include <stdexcept>

#include "analysis/tracking.hpp"
#include "io/output_folder.hpp"

namespace quadcosim::io {

namespace {
constexpr std::ptrdiff_t kJudgedColumns = 12;  // x .. yaw_des, the first of series_columns()
}  // namespace

const std::vector<std::string>& series_columns() {
  static const std::vector<std::string> names = {"x",     "y",     "z",        "roll",      "pitch",   "yaw",  "x_des",
                                                 "y_des", "z_des", "roll_des", "pitch_des", "yaw_des", "sat1", "sat2",
                                                 "sat3",  "sat4",  "tilt_sat", "U1",        "att_err", "cmd1", "cmd2",
                                                 "cmd3",  "cmd4",  "safety",   "watchdog"};
  return names;
}

Series read_series(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw std::runtime_error(path + ": cannot open");
  std::string line;
  if (!std::getline(in, line)) throw std::runtime_error(path + ": empty file");
  std::vector<std::string> header;
  {
    std::stringstream ss(line);
    for (std::string c; std::getline(ss, c, ',');) header.push_back(c);
  }
  const std::vector<std::string>& all = series_columns();
  const std::vector<std::string> wanted(all.begin(), all.begin() + kJudgedColumns);
  std::vector<int> index;
  auto column = [&](const std::string& name) {
    for (std::size_t i = 0; i < header.size(); ++i) {
      if (header[i] == name) return static_cast<int>(i);
    }
    throw std::runtime_error(path + ": no column '" + name + "'");
  };
  const int t_col = column("t");
  for (const auto& w : wanted) index.push_back(column(w));
  // Read when present: a trajectory from before the saturation columns existed still loads.
  std::vector<std::string> names = wanted;
  for (auto optional = all.begin() + kJudgedColumns; optional != all.end(); ++optional) {
    if (std::find(header.begin(), header.end(), *optional) == header.end()) continue;
    names.push_back(*optional);
    index.push_back(column(*optional));
  }
  Series s;
  int line_no = 1;
  std::vector<double> row;
  while (std::getline(in, line)) {
    ++line_no;
    row.clear();
    std::stringstream ss(line);
    for (std::string c; std::getline(ss, c, ',');) {
      char* end = nullptr;
      row.push_back(std::strtod(c.c_str(), &end));
      if (end == c.c_str()) throw std::runtime_error(path + ":" + std::to_string(line_no) + ": bad number '" + c + "'");
    }
    if (row.size() != header.size()) {
      throw std::runtime_error(path + ":" + std::to_string(line_no) + ": expected " + std::to_string(header.size()) +
                               " values");
    }
    s.t_s.push_back(row[t_col]);
    for (std::size_t i = 0; i < names.size(); ++i) s.append(names[i], row[index[i]]);
  }
  return s;
}

namespace {
bool is_angle(const std::string& channel) { return channel == "roll" || channel == "pitch" || channel == "yaw"; }

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
    options.angle = is_angle(spec.channel);
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
  std::array<double, 4> rotor{};
  double any = 0.0, tilt = 0.0, sum_du2 = 0.0;
  std::size_t n_u = 0;
  const double hover_n = sc.vehicle.mass_kg * sc.vehicle.gravity_m_s2;
  const auto u1 = v.find("U1");
  // Measured at the plant: the command acting over each tick against the vehicle's limits.
  std::array<const std::vector<double>*, 4> command{};
  for (int k = 0; k < 4; ++k) {
    const auto it = v.find("cmd" + std::to_string(k + 1));
    command[k] = it == v.end() ? nullptr : &it->second;
  }
  const auto safety = v.find("safety"), watchdog = v.find("watchdog");
  const bool measured =
      command[0] && command[1] && command[2] && command[3] && safety != v.end() && watchdog != v.end() && u1 != v.end();
  const model::MotorParams& motor = sc.vehicle.motor;
  double at_limit = 0.0;
  for (std::size_t i = 0; i < n; ++i) {
    const double dt = period(i);
    bool some = false;
    for (int k = 0; k < 4; ++k) {
      if (v.at("sat" + std::to_string(k + 1))[i] != 0.0) {
        rotor[k] += dt;
        some = true;
      }
    }
    if (some) any += dt;
    if (v.at("tilt_sat")[i] != 0.0) tilt += dt;
    // The controller's commands only: not before its first step (no U1 yet), nor the stale-data safety
    // command or the plant watchdog's (they stop the rotors on purpose).
    if (measured && std::isfinite(u1->second[i]) && safety->second[i] == 0.0 && watchdog->second[i] == 0.0) {
      for (int k = 0; k < 4; ++k) {
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
  for (int k = 0; k < 4; ++k) r.figures[SaturationResult::fmt_rotor(k + 1)] = rotor[k];
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
  for (int k = 1; k <= 4; ++k) {
    if (s.rotor_saturated_s(k) > 0.0) rotors += (rotors.empty() ? "" : ", ") + std::to_string(k);
    times += fmt::format("{}{:.3f}", k == 1 ? "" : "/", s.rotor_saturated_s(k));
  }
  std::string line = "warning: rotor saturation: ";
  std::string said;
  if (s.saturated_s() > 0.0) {
    said = fmt::format("rotor{} {} at omega_min/omega_max for {:.3f} s in total (rotors 1/2/3/4: {} s)",
                       rotors.size() > 1 ? "s" : "", rotors, s.saturated_s(), times);
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
         "; the response is the limits', not the controller's alone (sat1..4, tilt_sat, cmd1..4 in trajectory.csv)";
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

namespace {
nlohmann::json opt(const std::optional<double>& v) { return v ? nlohmann::json(*v) : nlohmann::json(); }

// Every figure of `names` by name: its value, or null when absent.
nlohmann::json figures_json(const std::vector<std::string>& names, const std::map<std::string, double>& figures) {
  nlohmann::json figs = nlohmann::json::object();
  for (const auto& name : names) {
    const auto it = figures.find(name);
    figs[name] = it == figures.end() ? nlohmann::json() : nlohmann::json(it->second);
  }
  return figs;
}

nlohmann::json criteria_json(const std::vector<CriterionResult>& criteria) {
  nlohmann::json a = nlohmann::json::array();
  for (const auto& c : criteria) {
    a.push_back({{"figure", c.criterion.figure},
                 {"set", to_string(c.criterion.set)},
                 {"min", opt(c.criterion.min)},
                 {"max", opt(c.criterion.max)},
                 {"value", opt(c.value)},
                 {"passed", c.passed},
                 {"judged", c.judged},
                 {"note", c.note.empty() ? nlohmann::json() : nlohmann::json(c.note)}});
  }
  return a;
}

// A block's (or the run's) verdict: null when nothing is judged (--judge none).
nlohmann::json verdict_json(Judge judge, bool passed) {
  return judge == Judge::kNone ? nlohmann::json() : nlohmann::json(passed);
}

template <class Result>
std::size_t count_judged(const Result& r) {
  return static_cast<std::size_t>(
      std::count_if(r.criteria.begin(), r.criteria.end(), [](const CriterionResult& c) { return c.judged; }));
}
}  // namespace

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

nlohmann::json metrics_json(const Scenario& scenario, const std::vector<StepResult>& results,
                            const std::optional<HoldResult>& hold, const std::optional<SaturationResult>& saturation,
                            const std::optional<TrackingResult>& tracking, Judge judge) {
  nlohmann::json j;
  j["scenario"] = scenario.name;
  j["description"] = scenario.description;
  j["scenario_file"] = scenario.path;
  j["judged"] = to_string(judge);
  j["judged_criteria"] = judged_criteria(results, hold, saturation, tracking);
  if (const std::string note = nothing_judged_note(scenario, judge); !note.empty()) j["judged_note"] = note;
  j["steps"] = nlohmann::json::array();
  for (const StepResult& r : results) {
    nlohmann::json s;
    s["channel"] = r.spec.channel;
    s["t_step_s"] = r.spec.t_step_s;
    s["initial"] = r.figures.initial;
    s["target"] = r.figures.target;
    s["step"] = r.figures.step;
    s["verdict"] = analysis::to_string(r.figures.verdict);
    s["post_step_s"] = r.figures.post_step_s;
    s["final_window_s"] = r.figures.final_window_s;
    s["settling_band_pct"] = r.spec.settling_band * 100.0;
    nlohmann::json figs = nlohmann::json::object();
    for (const auto& name : analysis::figure_names()) figs[name] = opt(analysis::figure(r.figures, name));
    s["figures"] = figs;
    s["criteria"] = criteria_json(r.criteria);
    if (!r.spec.reference.empty()) {
      nlohmann::json ref = {{"source", r.spec.reference_source}};
      for (const auto& [k, v] : r.spec.reference) ref[k] = v;
      s["reference"] = ref;
    }
    s["passed"] = verdict_json(judge, r.passed);
    j["steps"].push_back(s);
  }
  if (hold) {
    nlohmann::json h;
    h["after_s"] = hold->spec.after_s;
    h["figures"] = figures_json(hold_figure_names(), hold->figures);
    h["criteria"] = criteria_json(hold->criteria);
    h["passed"] = verdict_json(judge, hold->passed);
    j["hold"] = h;
  }
  if (saturation) {
    j["saturation"] = {{"figures", figures_json(saturation_figure_names(), saturation->figures)},
                       {"criteria", criteria_json(saturation->criteria)},
                       {"passed", verdict_json(judge, saturation->passed)}};
  }
  if (tracking) {
    j["tracking"] = {{"after_s", tracking->spec.after_s},
                     {"reference_period_s", tracking->spec.reference_period_s},
                     {"samples", tracking->samples},
                     {"figures", figures_json(analysis::tracking_figure_names(), tracking->figures)},
                     {"criteria", criteria_json(tracking->criteria)},
                     {"passed", verdict_json(judge, tracking->passed)}};
  }
  j["passed"] = verdict_json(judge, passed_overall(results, hold, saturation, tracking));
  return j;
}

void write_metrics_json(const std::string& path, const Scenario& scenario, const std::vector<StepResult>& results,
                        const std::optional<HoldResult>& hold, const std::optional<SaturationResult>& saturation,
                        const std::optional<TrackingResult>& tracking, Judge judge) {
  write_file_atomically(path, metrics_json(scenario, results, hold, saturation, tracking, judge).dump(2) + "\n");
}

namespace {
// The band and check of the figure `name` in one criteria set, and the notes of its criteria (several
// criteria may name it). The judged set's check reads ok/FAIL; the other's in/out (shown, not judged).
struct CriterionCells {
  std::string band, check;
  std::vector<std::string> notes;
};
CriterionCells cells(const std::vector<CriterionResult>& criteria, const std::string& name, CriteriaSet set) {
  CriterionCells c;
  for (const auto& r : criteria) {
    if (r.criterion.figure != name || r.criterion.set != set) continue;
    c.band = fmt::format("[{}, {}]", r.criterion.min ? fmt::format("{:g}", *r.criterion.min) : "-",
                         r.criterion.max ? fmt::format("{:g}", *r.criterion.max) : "-");
    c.check = r.judged ? (r.passed ? "ok" : "FAIL") : (r.passed ? "in" : "out");
    if (!r.note.empty()) c.notes.push_back(r.note);
  }
  return c;
}

// The header of a figure table: figure, value, the spec and paper columns, and `last` (reference).
// A table line without the padding of its empty last cells.
std::string trimmed_line(std::string line) {
  line.erase(line.find_last_not_of(' ') + 1);
  return line + "\n";
}

std::string header_row(const std::string& last) {
  return trimmed_line(fmt::format("  {:<24} {:>12} {:>18} {:<4} {:>18} {:<4} {:>10}", "figure", "value", "spec", "",
                                  "paper", "", last));
}

// One row: a figure's value, its spec band and check, its paper band and check, and `last`; then its notes.
std::string figure_row(const std::string& name, const std::string& value, const std::vector<CriterionResult>& criteria,
                       const std::string& last) {
  const CriterionCells spec = cells(criteria, name, CriteriaSet::kSpec);
  const CriterionCells paper = cells(criteria, name, CriteriaSet::kPaper);
  std::string s = trimmed_line(fmt::format("  {:<24} {:>12} {:>18} {:<4} {:>18} {:<4} {:>10}", name, value, spec.band,
                                           spec.check, paper.band, paper.check, last));
  for (const auto* c : {&spec, &paper}) {
    for (const auto& note : c->notes) s += fmt::format("    {}: {}\n", name, note);
  }
  return s;
}

// One table row per figure of `names` (value as `show` writes it, "-" when absent).
template <class Show>
std::string figure_rows(const std::vector<std::string>& names, const std::map<std::string, double>& figures,
                        const std::vector<CriterionResult>& criteria, Show show) {
  std::string s = header_row("");
  for (const auto& name : names) {
    const auto it = figures.find(name);
    s += figure_row(name, it != figures.end() ? show(it->second) : "-", criteria, "");
  }
  return s;
}
std::string fixed3(double v) { return fmt::format("{:.3f}", v); }

// A block's verdict: PASS or FAIL on the judged criteria, "figures only" under --judge none, "no spec
// criteria" (or paper bands) when the block has none of the judged set.
template <class Result>
std::string verdict_text(const Result& r, Judge judge) {
  if (judge == Judge::kNone) return "figures only";
  if (r.criteria.empty()) return "no criteria";
  if (count_judged(r) == 0) return judge == Judge::kSpec ? "no spec criteria" : "no paper bands";
  return r.passed ? "PASS" : "FAIL";
}
}  // namespace

std::string format_step_table(const Scenario& scenario, const std::vector<StepResult>& results,
                              const std::optional<HoldResult>& hold, const std::optional<SaturationResult>& saturation,
                              const std::optional<TrackingResult>& tracking, Judge judge) {
  std::string s = fmt::format("scenario {}\njudged against: {}\n", scenario.name, judged_set_text(judge));
  if (const std::string note = nothing_judged_note(scenario, judge); !note.empty()) s += note + "\n";
  for (const StepResult& r : results) {
    const auto& f = r.figures;
    const bool angle = is_angle(r.spec.channel);
    s += fmt::format(
        "step {} {:g} -> {:g}{} at t = {:g} s: {} ({}; final window {:g} s of {:g} s)\n", r.spec.channel, f.initial,
        f.target,
        angle && std::abs(f.step - (f.target - f.initial)) > 1e-12 ? fmt::format(" (shortest path {:+.3f})", f.step)
                                                                   : "",
        r.spec.t_step_s, verdict_text(r, judge), analysis::to_string(f.verdict), f.final_window_s, f.post_step_s);
    s += header_row("reference");
    for (const auto& name : analysis::figure_names()) {
      const auto v = analysis::figure(f, name);
      std::string value = v ? fmt::format("{:.3f}", *v) : "-";
      if (!v && name == "settling_time_2pct_s" && f.verdict == analysis::StepVerdict::kNotSettled)
        value = "not settled";
      if (!v && f.verdict == analysis::StepVerdict::kTooShort &&
          (name == "settling_time_2pct_s" || name == "steady_state_error_pct")) {
        value = "too short";
      }
      const auto ref = r.spec.reference.find(name);
      s += figure_row(name, value, r.criteria, ref != r.spec.reference.end() ? fmt::format("{:g}", ref->second) : "");
    }
  }
  if (hold) {
    s += fmt::format("hold from t = {:g} s: {}\n", hold->spec.after_s, verdict_text(*hold, judge));
    s += figure_rows(hold_figure_names(), hold->figures, hold->criteria, fixed3);
  }
  if (saturation) {
    s +=
        fmt::format("limits (rotor speed and tilt saturation, control effort): {}\n", verdict_text(*saturation, judge));
    s += figure_rows(saturation_figure_names(), saturation->figures, saturation->criteria, fixed3);
  }
  if (tracking) {
    s += fmt::format("tracking from t = {:g} s ({} samples, at the controller's steps every {:g} s): {}\n",
                     tracking->spec.after_s, tracking->samples, tracking->spec.reference_period_s,
                     verdict_text(*tracking, judge));
    s += figure_rows(analysis::tracking_figure_names(), tracking->figures, tracking->criteria,
                     [](double v) { return fmt::format("{:.4g}", v); });
  }
  if (has_criteria(scenario, CriteriaSet::kPaper)) {
    s += "paper: the paper's controller's response (bands around its measured figures), not a specification; "
         "spec: bounds a good controller must meet\n";
  }
  return s;
}

}  // namespace quadcosim::io
