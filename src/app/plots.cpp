#include <sys/wait.h>

#include <cstdlib>
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

bool make_plots(const std::string& run_dir) {
  // Debian's matplotlib lives with the system interpreter, so that is the default.
  const std::string python = env_or("QUADCOSIM_PYTHON", "/usr/bin/python3");
  const std::string script = env_or("QUADCOSIM_PLOT_SCRIPT", QUADCOSIM_PLOT_SCRIPT);
  const std::string cmd = shell_quote(python) + " " + shell_quote(script) + " " + shell_quote(run_dir);
  std::cout.flush();
  const int status = std::system(cmd.c_str());
  if (status != 0) {
    std::cerr << "error: plotting failed (" << cmd << "); install python3-matplotlib or pass --no-plots\n";
    return false;
  }
  return true;
}

}  // namespace quadcosim::app
