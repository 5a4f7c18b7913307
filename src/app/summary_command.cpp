// `quadcosim summary RUN_DIR... [--out FILE.md]`: our step figures beside the reference ones.
#include <fmt/format.h>
#include <CLI/CLI.hpp>

#include <filesystem>
#include <fstream>
#include <iostream>
#include <nlohmann/json.hpp>

#include "app/commands.hpp"
#include "app/exit_codes.hpp"

namespace quadcosim::app {

namespace {
std::string num(const nlohmann::json& v) { return v.is_number() ? fmt::format("{:.2f}", v.get<double>()) : "-"; }
// The set of a criterion of metrics.json; one written before the sets existed is a spec.
std::string set_of(const nlohmann::json& c) { return c.value("set", std::string("spec")); }
std::string band(const nlohmann::json& criteria, const std::string& fig, const std::string& set) {
  for (const auto& c : criteria) {
    if (c.value("figure", "") != fig || set_of(c) != set) continue;
    const std::string lo = c["min"].is_number() ? fmt::format("{:g}", c["min"].get<double>()) : "";
    const std::string hi = c["max"].is_number() ? fmt::format("{:g}", c["max"].get<double>()) : "";
    if (lo.empty() && hi.empty()) return "any";
    if (lo.empty()) return "≤ " + hi;
    if (hi.empty()) return "≥ " + lo;
    return lo + " – " + hi;
  }
  return "";
}
}  // namespace

CLI::App* add_summary_subcommand(CLI::App& app, SummaryOptions& sum) {
  auto* sum_cmd = app.add_subcommand("summary", "table of step figures of several runs (ours beside the paper's)");
  sum_cmd->add_option("run_dirs", sum.run_dirs, "run directories (with metrics.json)")->required();
  sum_cmd->add_option("--out", sum.out, "also write the table to this Markdown file");
  return sum_cmd;
}

int summary_command(const SummaryOptions& opt) {
  const std::vector<std::pair<std::string, std::string>> figs = {{"overshoot_pct", "overshoot %"},
                                                                 {"peak_time_s", "peak s"},
                                                                 {"t95_s", "95 % s"},
                                                                 {"settling_time_2pct_s", "2 % settling s"},
                                                                 {"steady_state_error_pct", "error %"}};
  std::string md =
      "| run | judged | step | figure | ours | reference | spec | paper | verdict |\n"
      "|---|---|---|---|---|---|---|---|---|\n";
  bool all_ok = true;
  for (const auto& dir : opt.run_dirs) {
    const auto path = std::filesystem::path(dir) / "metrics.json";
    std::ifstream in(path);
    nlohmann::json j;
    try {
      if (!in) throw std::runtime_error("cannot open");
      in >> j;
    } catch (const std::exception& e) {
      std::cerr << "error: " << path.string() << ": " << e.what() << '\n';
      return exit_code::kBadInput;
    }
    const std::string judged = j.value("judged", std::string("spec"));  // before --judge: the one set, a spec
    for (const auto& s : j.value("steps", nlohmann::json::array())) {
      const std::string step =
          fmt::format("{} {:g} → {:g}", s.value("channel", "?"), s.value("initial", 0.0), s.value("target", 0.0));
      const auto ref = s.value("reference", nlohmann::json::object());
      for (const auto& [key, label] : figs) {
        // The verdict is the judged set's; the other set's band is shown, not judged.
        std::string verdict;
        for (const auto& c : s["criteria"]) {
          if (c.value("figure", "") == key && c.value("judged", true)) {
            verdict = c.value("passed", false) ? "pass" : "**FAIL**";
          }
        }
        md += fmt::format("| {} | {} | {} | {} | {} | {} | {} | {} | {} |\n", j.value("scenario", dir), judged, step,
                          label, num(s["figures"][key]), ref.contains(key) ? num(ref[key]) : "",
                          band(s["criteria"], key, "spec"), band(s["criteria"], key, "paper"), verdict);
      }
    }
    // No verdict (--judge none: "passed" is null) fails nothing.
    const nlohmann::json passed = j.contains("passed") ? j["passed"] : nlohmann::json(false);
    all_ok = all_ok && (passed.is_null() || (passed.is_boolean() && passed.get<bool>()));
  }
  std::cout << md;
  if (!opt.out.empty()) {
    std::ofstream out(opt.out);
    out << "# Step figures: quadcosim beside the paper\n\n"
        << "Reference values are read off the paper's text for Figs. 4-7. \"spec\" is the scenario's "
           "specification (bounds a good controller must meet); \"paper\" is the paper's controller's response "
           "(bands around its measured figures, not a specification). \"judged\" names the set each run was "
           "judged against (`quadcosim run --judge`); the verdict is that set's.\n\n"
        << md;
    if (!out) {
      std::cerr << "error: cannot write " << opt.out << '\n';
      return exit_code::kOutput;
    }
  }
  return all_ok ? exit_code::kOk : exit_code::kFailed;
}

}  // namespace quadcosim::app
