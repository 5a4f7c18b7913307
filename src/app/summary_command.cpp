// `quadcosim summary RUN_DIR... [--out FILE.md]`: the figures of several runs in one table, each row
// labelled by its run folder and the controller that flew it.
#include <fmt/format.h>
#include <CLI/CLI.hpp>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <nlohmann/json.hpp>

#include "app/commands.hpp"
#include "app/exit_codes.hpp"
#include "io/provenance.hpp"

namespace quadcosim::app {

namespace {
std::string num(const nlohmann::json& v, const char* format) {
  return v.is_number() ? fmt::format(fmt::runtime(format), v.get<double>()) : "-";
}
// The set of a criterion of metrics.json; one written before the sets existed is a spec.
std::string set_of(const nlohmann::json& c) { return c.value("set", std::string("spec")); }
// The band of `fig` in `set`: "" when the scenario sets none, "any" when it sets one without bounds.
std::string band(const nlohmann::json& criteria, const std::string& fig, const std::string& set) {
  if (!criteria.is_array()) return "";
  for (const auto& c : criteria) {
    if (!c.is_object() || c.value("figure", "") != fig || set_of(c) != set) continue;
    const std::string lo = c["min"].is_number() ? fmt::format("{:g}", c["min"].get<double>()) : "";
    const std::string hi = c["max"].is_number() ? fmt::format("{:g}", c["max"].get<double>()) : "";
    if (lo.empty() && hi.empty()) return "any";
    if (lo.empty()) return "≤ " + hi;
    if (hi.empty()) return "≥ " + lo;
    return lo + " – " + hi;
  }
  return "";
}
// The verdict is the judged set's; the other set's band is shown, not judged.
std::string verdict(const nlohmann::json& criteria, const std::string& fig) {
  if (!criteria.is_array()) return "";
  std::string v;
  for (const auto& c : criteria) {
    if (c.is_object() && c.value("figure", "") == fig && c.value("judged", true)) {
      v = c.value("passed", false) ? "pass" : "**FAIL**";
    }
  }
  return v;
}
std::string seconds(const nlohmann::json& section) {
  const nlohmann::json after = section.value("after_s", nlohmann::json());
  return after.is_number() ? fmt::format("{:g}", after.get<double>()) : "?";
}
}  // namespace

CLI::App* add_summary_subcommand(CLI::App& app, SummaryOptions& sum) {
  auto* sum_cmd = app.add_subcommand(
      "summary", "table of the figures of several runs (steps, hold, tracking), by run folder and controller");
  sum_cmd->add_option("run_dirs", sum.run_dirs, "run directories (with metrics.json)")->required();
  sum_cmd->add_option("--out", sum.out, "also write the table to this Markdown file");
  return sum_cmd;
}

int summary_command(const SummaryOptions& opt) {
  const std::vector<std::pair<std::string, std::string>> step_figs = {{"overshoot_pct", "overshoot %"},
                                                                      {"peak_time_s", "peak s"},
                                                                      {"t95_s", "95 % s"},
                                                                      {"settling_time_2pct_s", "2 % settling s"},
                                                                      {"steady_state_error_pct", "error %"}};
  // A tracking run's headline figures; any other tracking figure a criterion judges is added.
  const std::vector<std::pair<std::string, std::string>> tracking_figs = {{"position_rmse_m", "position RMSE m"},
                                                                          {"position_max_m", "position max m"}};
  std::string md =
      "| run | controller | judged | what | figure | value | reference | spec | paper | verdict |\n"
      "|---|---|---|---|---|---|---|---|---|---|\n";
  bool all_ok = true;
  for (const auto& dir : opt.run_dirs) {
    const auto path = std::filesystem::path(dir) / "metrics.json";
    std::ifstream in(path);
    nlohmann::json j;
    try {
      if (!in) throw std::runtime_error("cannot open (not a run directory?)");
      in >> j;
      if (!j.is_object()) throw std::runtime_error("not a JSON object");
    } catch (const std::exception& e) {
      std::cerr << "error: " << path.string() << ": " << e.what() << '\n';
      return exit_code::kBadInput;
    }
    // The run by its folder, the controller by what flew (provenance; "?" in a run written before it).
    std::string controller = io::controller_label(j.value("provenance", nlohmann::json::object()));
    if (controller.empty()) controller = "?";
    const std::string judged = j.value("judged", std::string("spec"));  // before --judge: the one set, a spec
    const auto row = [&](const std::string& what, const std::string& figure, const std::string& key,
                         const std::string& value, const nlohmann::json& criteria, const std::string& reference) {
      md += fmt::format("| {} | {} | {} | {} | {} | {} | {} | {} | {} | {} |\n", dir, controller, judged, what, figure,
                        value, reference, band(criteria, key, "spec"), band(criteria, key, "paper"),
                        verdict(criteria, key));
    };
    const std::size_t rows_before = md.size();
    if (const auto tr = j.find("tracking"); tr != j.end() && tr->is_object()) {
      const std::string what = "tracking from t = " + seconds(*tr) + " s";
      const nlohmann::json figures = tr->value("figures", nlohmann::json::object());
      const nlohmann::json criteria = tr->value("criteria", nlohmann::json::array());
      auto shown = tracking_figs;
      for (const auto& c : criteria) {
        const std::string f = c.is_object() ? c.value("figure", "") : "";
        if (!f.empty() && std::none_of(shown.begin(), shown.end(), [&](const auto& p) { return p.first == f; }))
          shown.push_back({f, f});
      }
      for (const auto& [key, label] : shown) {
        row(what, label, key, num(figures.value(key, nlohmann::json()), "{:.4g}"), criteria, "");
      }
    }
    for (const auto& s : j.value("steps", nlohmann::json::array())) {
      const std::string step =
          fmt::format("{} step {:g} → {:g}", s.value("channel", "?"), s.value("initial", 0.0), s.value("target", 0.0));
      const auto ref = s.value("reference", nlohmann::json::object());
      const nlohmann::json figures = s.value("figures", nlohmann::json::object());
      const nlohmann::json criteria = s.value("criteria", nlohmann::json::array());
      for (const auto& [key, label] : step_figs) {
        row(step, label, key, num(figures.value(key, nlohmann::json()), "{:.2f}"), criteria,
            ref.contains(key) ? num(ref[key], "{:.2f}") : "");
      }
    }
    if (const auto h = j.find("hold"); h != j.end() && h->is_object()) {
      const std::string what = "hold from t = " + seconds(*h) + " s";
      const nlohmann::json criteria = h->value("criteria", nlohmann::json::array());
      for (const auto& [key, value] : h->value("figures", nlohmann::json::object()).items()) {
        row(what, key, key, num(value, "{:.4g}"), criteria, "");
      }
    }
    if (md.size() == rows_before) row("no steps, hold or tracking", "-", "-", "-", nlohmann::json::array(), "");
    // No verdict (--judge none: "passed" is null) fails nothing.
    const nlohmann::json passed = j.contains("passed") ? j["passed"] : nlohmann::json(false);
    all_ok = all_ok && (passed.is_null() || (passed.is_boolean() && passed.get<bool>()));
  }
  std::cout << md;
  if (!opt.out.empty()) {
    std::ofstream out(opt.out);
    out << "# Run figures\n\n"
        << "One row per figure of each run: the run folder, the controller that flew it (metrics.json "
           "\"provenance\"), the set it was judged against (`quadcosim run --judge`), the tracking, step and hold "
           "figures. \"reference\" is a published figure the scenario quotes for a step. \"spec\" is the "
           "scenario's specification (bounds a good controller must meet); \"paper\" the paper controller's "
           "response (bands around its measured figures, not a specification). The verdict is the judged "
           "set's.\n\n"
        << md;
    if (!out) {
      std::cerr << "error: cannot write " << opt.out << '\n';
      return exit_code::kOutput;
    }
  }
  return all_ok ? exit_code::kOk : exit_code::kFailed;
}

}  // namespace quadcosim::app
