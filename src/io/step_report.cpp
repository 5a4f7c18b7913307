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
                                                 "cmd3",  "cmd4",  "safety",   "watchdog",  "vz",      "sat5", "sat6",
                                                 "sat7",  "sat8",  "cmd5",     "cmd6",      "cmd7",    "cmd8"};
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

}  // namespace

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
    j["saturation"] = {{"figures", figures_json(saturation_figure_names(saturation->rotors), saturation->figures)},
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
    const bool angle = is_angle_channel(r.spec.channel);
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
    s += figure_rows(saturation_figure_names(saturation->rotors), saturation->figures, saturation->criteria, fixed3);
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
