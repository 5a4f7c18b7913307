// The Python tools (tools/*.py: plots, report, comparison) run with Debian's /usr/bin/python3,
// where python3-matplotlib lives.
#include <sys/wait.h>

#include <cstdlib>
#include <filesystem>
#include <iostream>
#include <string>

#include "app/commands.hpp"

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
  const std::string tools = env_or("QUADCOSIM_TOOLS_DIR", QUADCOSIM_TOOLS_DIR);
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

bool make_plots(const std::string& run_dir) {
  // The report embeds the figures, so it comes after them.
  return run_tool("plot_run.py", {run_dir}) &&
         run_tool("report.py", {run_dir, "--version-text", std::string("quadcosim ") + QUADCOSIM_VERSION});
}

namespace {
// "" when `dir` holds a run's trajectory.csv, else the error to print (bad input: exit 2).
std::string check_run_dir(const std::string& what, const std::string& dir) {
  if (std::filesystem::is_regular_file(std::filesystem::path(dir) / "trajectory.csv")) return {};
  return "error: " + what + ": " + dir + " is not a run directory (no trajectory.csv; expected the --out "
         "directory of `quadcosim run`)";
}
}  // namespace

int plot_command(const std::string& run_dir) {
  if (std::string err = check_run_dir("run_dir", run_dir); !err.empty()) {
    std::cerr << err << '\n';
    return 2;
  }
  return make_plots(run_dir) ? 0 : 3;
}

int compare_command(const std::string& run_a, const std::string& run_b, const std::string& out) {
  for (const auto& [what, dir] : {std::pair{"run_a", run_a}, std::pair{"run_b", run_b}}) {
    if (std::string err = check_run_dir(what, dir); !err.empty()) {
      std::cerr << err << '\n';
      return 2;
    }
  }
  std::vector<std::string> args = {run_a, run_b};
  if (!out.empty()) {
    args.push_back("--out");
    args.push_back(out);
  }
  return run_tool("compare_runs.py", args) ? 0 : 3;
}

}  // namespace quadcosim::app
