// The Python tools (tools/*.py: plots, report, comparison) run with Debian's /usr/bin/python3,
// where python3-matplotlib lives.
#include <sys/wait.h>
#include <CLI/CLI.hpp>

#include <cstdlib>
#include <filesystem>
#include <iostream>
#include <string>

#include "app/commands.hpp"
#include "app/exit_codes.hpp"
#include "app/resources.hpp"
#include "io/output_folder.hpp"

namespace quadcosim::app {

namespace {
std::string env_or(const char* name, const char* fallback) {
  const char* v = std::getenv(name);
  return v && *v ? v : fallback;
}

std::string shell_quote(const std::string& s) {
  std::string q = "'";
  for (char c : s) q += c == '\'' ? std::string("'\\''") : std::string(1, c);
  return q + "'";
}
}  // namespace

bool run_tool(const std::string& script, const std::vector<std::string>& args) {
  const std::string python = env_or("QUADCOSIM_PYTHON", "/usr/bin/python3");
  const std::string tools = tools_dir().string();
  std::string cmd = shell_quote(python);
  cmd += ' ';
  cmd += shell_quote(tools + "/" + script);
  for (const auto& a : args) {
    cmd += ' ';
    cmd += shell_quote(a);
  }
  std::cout.flush();
  const int status = std::system(cmd.c_str());
  if (status != 0) {
    std::cerr << "error: " << script << " failed (" << cmd
              << "); it needs /usr/bin/python3 with python3-matplotlib (scripts/install-deps.sh)\n";
    return false;
  }
  return true;
}

bool make_plots(const std::string& run_dir, io::OutputFolder& folder) {
  folder.record("outputs");
  // The report embeds the figures, so it comes after them.
  const bool ok = run_tool("plot_run.py", {run_dir}) &&
                  run_tool("report.py", {run_dir, "--version-text", std::string("quadcosim ") + QUADCOSIM_VERSION});
  folder.record("figures");
  return ok;
}

namespace {
// "" when `dir` holds a run's trajectory.csv, else the error to print (bad input: exit 2).
std::string check_run_dir(const std::string& what, const std::string& dir) {
  // plot_run.py and report.py read both; name the missing one here rather than let Python fail.
  for (const char* file : {"trajectory.csv", "metrics.json"}) {
    if (!std::filesystem::is_regular_file(std::filesystem::path(dir) / file)) {
      return "error: " + what + ": " + dir + " is not a run directory (no " + file +
             "; expected the --out directory of `quadcosim run`)";
    }
  }
  return {};
}
}  // namespace

CLI::App* add_plot_subcommand(CLI::App& app, PlotOptions& plot) {
  auto* plot_cmd = app.add_subcommand("plot",
                                      "regenerate a run directory's figures and report.html (the figures a "
                                      "previous plot wrote there are removed first)");
  plot_cmd->add_option("run_dir", plot.run_dir, "run directory (trajectory.csv, metrics.json)")
      ->required()
      ->check(CLI::ExistingDirectory);
  return plot_cmd;
}

CLI::App* add_compare_subcommand(CLI::App& app, CompareOptions& compare) {
  auto* cmp_cmd =
      app.add_subcommand("compare", "overlay two runs (e.g. two gain sets) and tabulate their step figures");
  cmp_cmd->add_option("run_a", compare.run_a, "first run directory")->required()->check(CLI::ExistingDirectory);
  cmp_cmd->add_option("run_b", compare.run_b, "second run directory")->required()->check(CLI::ExistingDirectory);
  cmp_cmd->add_option("--out", compare.out,
                      "output directory (default: RUN_B/compare_with_<RUN_A>); new or empty, or a previous "
                      "compare's, whose files are replaced");
  cmp_cmd->add_flag("--force", compare.force,
                    "write into a folder holding other outputs or files: remove the outputs its manifest lists "
                    "(files quadcosim did not write are kept)");
  return cmp_cmd;
}

int plot_command(const PlotOptions& o) {
  if (std::string err = check_run_dir("run_dir", o.run_dir); !err.empty()) {
    std::cerr << err << '\n';
    return exit_code::kBadInput;
  }
  io::OutputFolder folder = io::OutputFolder::reopen(o.run_dir, "plot", "figures");
  return make_plots(o.run_dir, folder) ? exit_code::kOk : exit_code::kOutput;
}

int compare_command(const CompareOptions& o) {
  for (const auto& [what, dir] : {std::pair{"run_a", o.run_a}, std::pair{"run_b", o.run_b}}) {
    if (std::string err = check_run_dir(what, dir); !err.empty()) {
      std::cerr << err << '\n';
      return exit_code::kBadInput;
    }
  }
  std::string out = o.out;
  if (out.empty()) {  // as compare_runs.py names it
    std::filesystem::path a = std::filesystem::absolute(o.run_a).lexically_normal();
    if (!a.has_filename()) a = a.parent_path();
    out = (std::filesystem::path(o.run_b) / ("compare_with_" + a.filename().string())).string();
  }
  io::OutputFolder folder = io::OutputFolder::claim(out, "compare", {.force = o.force, .replace_own = true}, std::cerr);
  const bool ok = run_tool("compare_runs.py", {o.run_a, o.run_b, "--out", out});
  folder.record("outputs");
  return ok ? exit_code::kOk : exit_code::kOutput;
}

}  // namespace quadcosim::app
