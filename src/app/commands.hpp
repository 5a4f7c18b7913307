// The quadcosim subcommands. Each returns the process exit code: 0 success, 1 a step criterion
// failed, 2 bad input (file, flag), 3 an output could not be produced.
#pragma once

#include <string>
#include <vector>

namespace quadcosim::app {

struct RunOptions {
  std::string scenario;
  std::string out_dir;
  bool plots = true;
};
int run_command(const RunOptions& options);

struct OpenloopOptions {
  std::string commands;
  std::string out;
  std::string vehicle;        ///< "" for the paper's vehicle
  double rate_hz = 100.0;
  int substeps = 1;
  double duration_s = -1.0;   ///< < 0: until the last command row's time
  double initial_z_m = 0.0;
};
int openloop_command(const OpenloopOptions& options);

struct LqrOptions {
  std::string params;   ///< controller parameter file, "" for defaults
  std::string vehicle;  ///< vehicle file, "" for the paper's vehicle
};
int lqr_command(const LqrOptions& options);

/// Lists the controller parameters (name, unit, range, default, meaning).
int params_command();

struct SummaryOptions {
  std::vector<std::string> run_dirs;
  std::string out;  ///< markdown file, "" for stdout only
};
int summary_command(const SummaryOptions& options);

/// Runs the plotting script on a run directory; returns false (after printing why) on failure.
bool make_plots(const std::string& run_dir);

}  // namespace quadcosim::app
