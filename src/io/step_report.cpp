#include "io/step_report.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <fstream>
#include <sstream>
#include <nlohmann/json.hpp>
#include <stdexcept>

namespace quadcosim::io {

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
  const std::vector<std::string> wanted = {"x",      "y",     "z",     "roll",      "pitch",     "yaw",
                                           "x_des",  "y_des", "z_des", "roll_des",  "pitch_des", "yaw_des"};
  std::vector<int> index;
  auto column = [&](const std::string& name) {
    for (std::size_t i = 0; i < header.size(); ++i) {
      if (header[i] == name) return static_cast<int>(i);
    }
    throw std::runtime_error(path + ": no column '" + name + "'");
  };
  const int t_col = column("t");
  for (const auto& w : wanted) index.push_back(column(w));
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
      throw std::runtime_error(path + ":" + std::to_string(line_no) + ": expected " +
                               std::to_string(header.size()) + " values");
    }
    s.t_s.push_back(row[t_col]);
    for (std::size_t i = 0; i < wanted.size(); ++i) s.append(wanted[i], row[index[i]]);
  }
  return s;
}

std::vector<StepResult> evaluate_steps(const std::vector<StepSpec>& steps, const Series& series) {
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
    r.figures = analysis::step_figures(series.t_s, y->second, spec.t_step_s, sp->second[i]);
    for (const Criterion& c : spec.criteria) {
      CriterionResult cr{c, analysis::figure(r.figures, c.figure), false};
      cr.passed = cr.value.has_value() && (!c.min || *cr.value >= *c.min) && (!c.max || *cr.value <= *c.max);
      r.passed = r.passed && cr.passed;
      r.criteria.push_back(cr);
    }
    out.push_back(r);
  }
  return out;
}

bool all_passed(const std::vector<StepResult>& results) {
  return std::all_of(results.begin(), results.end(), [](const auto& r) { return r.passed; });
}

HoldResult evaluate_hold(const HoldSpec& spec, const Series& series) {
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
  for (const Criterion& c : spec.criteria) {
    const auto it = r.figures.find(c.figure);
    CriterionResult cr{c, it == r.figures.end() ? std::nullopt : std::optional<double>(it->second), false};
    cr.passed = cr.value.has_value() && (!c.min || *cr.value >= *c.min) && (!c.max || *cr.value <= *c.max);
    r.passed = r.passed && cr.passed;
    r.criteria.push_back(cr);
  }
  return r;
}

namespace {
nlohmann::json opt(const std::optional<double>& v) { return v ? nlohmann::json(*v) : nlohmann::json(); }
}  // namespace

nlohmann::json metrics_json(const Scenario& scenario, const std::vector<StepResult>& results,
                            const std::optional<HoldResult>& hold) {
  nlohmann::json j;
  j["scenario"] = scenario.name;
  j["description"] = scenario.description;
  j["scenario_file"] = scenario.path;
  j["steps"] = nlohmann::json::array();
  for (const StepResult& r : results) {
    nlohmann::json s;
    s["channel"] = r.spec.channel;
    s["t_step_s"] = r.spec.t_step_s;
    s["initial"] = r.figures.initial;
    s["target"] = r.figures.target;
    nlohmann::json figs = nlohmann::json::object();
    for (const auto& name : analysis::figure_names()) figs[name] = opt(analysis::figure(r.figures, name));
    s["figures"] = figs;
    s["criteria"] = nlohmann::json::array();
    for (const auto& c : r.criteria) {
      s["criteria"].push_back({{"figure", c.criterion.figure},
                               {"min", opt(c.criterion.min)},
                               {"max", opt(c.criterion.max)},
                               {"value", opt(c.value)},
                               {"passed", c.passed}});
    }
    if (!r.spec.reference.empty()) {
      nlohmann::json ref = {{"source", r.spec.reference_source}};
      for (const auto& [k, v] : r.spec.reference) ref[k] = v;
      s["reference"] = ref;
    }
    s["passed"] = r.passed;
    j["steps"].push_back(s);
  }
  if (hold) {
    nlohmann::json h;
    h["after_s"] = hold->spec.after_s;
    nlohmann::json figs = nlohmann::json::object();
    for (const auto& name : hold_figure_names()) {
      const auto it = hold->figures.find(name);
      figs[name] = it == hold->figures.end() ? nlohmann::json() : nlohmann::json(it->second);
    }
    h["figures"] = figs;
    h["criteria"] = nlohmann::json::array();
    for (const auto& c : hold->criteria) {
      h["criteria"].push_back({{"figure", c.criterion.figure},
                               {"min", opt(c.criterion.min)},
                               {"max", opt(c.criterion.max)},
                               {"value", opt(c.value)},
                               {"passed", c.passed}});
    }
    h["passed"] = hold->passed;
    j["hold"] = h;
  }
  j["passed"] = all_passed(results) && (!hold || hold->passed);
  return j;
}

void write_metrics_json(const std::string& path, const Scenario& scenario,
                        const std::vector<StepResult>& results, const std::optional<HoldResult>& hold) {
  std::ofstream out(path);
  out << metrics_json(scenario, results, hold).dump(2) << '\n';
  if (!out) throw std::runtime_error(path + ": write failed");
}

std::string format_step_table(const Scenario& scenario, const std::vector<StepResult>& results,
                              const std::optional<HoldResult>& hold) {
  std::string s = fmt::format("scenario {}\n", scenario.name);
  for (const StepResult& r : results) {
    s += fmt::format("step {} {:g} -> {:g} at t = {:g} s: {}\n", r.spec.channel, r.figures.initial,
                     r.figures.target, r.spec.t_step_s, r.passed ? "PASS" : "FAIL");
    s += fmt::format("  {:<24} {:>10} {:>22} {:>7} {:>10}\n", "figure", "value", "criterion", "", "reference");
    for (const auto& name : analysis::figure_names()) {
      const auto v = analysis::figure(r.figures, name);
      std::string crit, verdict;
      for (const auto& c : r.criteria) {
        if (c.criterion.figure != name) continue;
        crit = fmt::format("[{}, {}]", c.criterion.min ? fmt::format("{:g}", *c.criterion.min) : "-",
                           c.criterion.max ? fmt::format("{:g}", *c.criterion.max) : "-");
        verdict = c.passed ? "ok" : "FAIL";
      }
      const auto ref = r.spec.reference.find(name);
      s += fmt::format("  {:<24} {:>10} {:>22} {:>7} {:>10}\n", name, v ? fmt::format("{:.3f}", *v) : "-",
                       crit, verdict, ref != r.spec.reference.end() ? fmt::format("{:g}", ref->second) : "");
    }
  }
  if (hold) {
    s += fmt::format("hold from t = {:g} s: {}\n", hold->spec.after_s, hold->passed ? "PASS" : "FAIL");
    for (const auto& name : hold_figure_names()) {
      const auto it = hold->figures.find(name);
      std::string crit, verdict;
      for (const auto& c : hold->criteria) {
        if (c.criterion.figure != name) continue;
        crit = fmt::format("[{}, {}]", c.criterion.min ? fmt::format("{:g}", *c.criterion.min) : "-",
                           c.criterion.max ? fmt::format("{:g}", *c.criterion.max) : "-");
        verdict = c.passed ? "ok" : "FAIL";
      }
      s += fmt::format("  {:<24} {:>10} {:>22} {:>7}\n", name,
                       it != hold->figures.end() ? fmt::format("{:.3f}", it->second) : "-", crit, verdict);
    }
  }
  return s;
}

}  // namespace quadcosim::io
