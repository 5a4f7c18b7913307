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
  std::string transport = "inproc";  ///< "inproc" or "dds" (plant and controller as two processes)
  bool realtime = false;             ///< dds: real time instead of lockstep
  double rate_factor = 1.0;          ///< dds real time: k times faster than the wall clock
  double timeout_s = 10.0;           ///< dds: lockstep wait for one command before the policy applies
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

struct PlantCommandOptions {
  std::string scenario;     ///< vehicle, rates, duration, initial state ("" for defaults)
  std::string ns;           ///< overrides the scenario's namespace when set
  bool lockstep = true;     ///< false: real time
  double rate_factor = 1.0; ///< real time: run k times faster than the wall clock
  double duration_s = -1.0; ///< overrides the scenario's duration when >= 0
  std::string record;       ///< trajectory CSV to write ("" for none)
  double timeout_s = 10.0;  ///< lockstep: how long to wait for a controller / for one command
  std::string on_timeout = "abort";  ///< lockstep: "abort" (exit 4) or "hold" (last command, go on)
  bool wait_for_controller = false;  ///< real time: start the clock only once a controller is matched
};
int plant_command(const PlantCommandOptions& options);

struct ControllerCommandOptions {
  std::string scenario;  ///< controller parameters, rates, schedule ("" for defaults)
  std::string params;    ///< controller parameter file, applied over the scenario's
  std::string ns;
  bool lockstep = true;
  double rate_factor = 1.0;  ///< real time: the timer runs k times faster (to match a faster plant)
};
int controller_command(const ControllerCommandOptions& options);

/// Runs the plotting script on a run directory; returns false (after printing why) on failure.
bool make_plots(const std::string& run_dir);

}  // namespace quadcosim::app
