// The quadcosim subcommands. Each command file registers its subcommand with
// add_<name>_subcommand(app, options) (the options it parses into) and runs it with
// <name>_command(options), which returns the process exit code (app/exit_codes.hpp: the values
// and, per command, what they mean); main.cpp runs it under run_guarded, which maps what it throws.
#pragma once

#include <cstdint>
#include <initializer_list>
#include <string>
#include <vector>

#include "controllers/registry.hpp"
#include "hosts/bench.hpp"
#include "hosts/node_options.hpp"
#include "hosts/recorder_process.hpp"
#include "hosts/topic_process.hpp"
#include "io/scenario_resolvers.hpp"

namespace CLI {
class App;
class Option;
}  // namespace CLI
namespace quadcosim::io {
class OutputFolder;
}

namespace quadcosim::app {

/// `--foxglove [ADDR:]PORT` and its companions (run, plant, controller): hosts/node_options.hpp.
using FoxgloveCliOptions = hosts::FoxgloveOptions;

struct RunOptions {
  std::string scenario;
  std::string controller;  ///< --controller: replaces the scenario's controller.type ("" keeps it)
  std::string out_dir;
  bool force = false;  ///< replace a previous command's outputs in out_dir (io/output_folder.hpp)
  bool plots = true;
  std::string transport = "inproc";  ///< "inproc" or "dds" (plant and controller as two processes)
  bool realtime = false;             ///< dds: real time instead of lockstep
  double rate_factor = 1.0;          ///< dds real time: k times faster than the wall clock
  double timeout_s = 10.0;           ///< dds: lockstep wait for one command before the policy applies
  int vehicles = 0;                  ///< > 0: a swarm of this many vehicles (overrides swarm.vehicles)
  int threads = 0;                   ///< > 0: in-process swarm threads (overrides swarm.threads)
  bool pin = false;                  ///< dds: plant and controller each on its own CPU (--cpus)
  /// dds: run secured (Enforce) with this SROS2 keystore; created when missing, as are the enclaves
  /// /quadcosim/plant and /quadcosim/controller ("" = as the ROS_SECURITY_* environment says).
  std::string keystore;
  FoxgloveCliOptions foxglove;
  /// --judge: the criteria set the run is judged against: spec (the scenario's specification), paper
  /// (the paper controller's measured bands) or none (figures only; exit 0 whatever they are).
  std::string judge = "spec";
};
int run_command(const RunOptions& options, const io::ScenarioResolvers& resolvers);
CLI::App* add_run_subcommand(CLI::App& app, RunOptions& options);

struct OpenloopOptions {
  std::string commands;
  std::string out;
  std::string vehicle;  ///< "" for the paper's vehicle
  double rate_hz = 100.0;
  int substeps = 1;
  double duration_s = -1.0;  ///< < 0: until the last command row's time
  double initial_z_m = 0.0;
};
int openloop_command(const OpenloopOptions& options);
CLI::App* add_openloop_subcommand(CLI::App& app, OpenloopOptions& options);

struct LqrOptions {
  std::string params;   ///< controller parameter file, "" for defaults
  std::string vehicle;  ///< vehicle file, "" for the paper's vehicle
};
int lqr_command(const LqrOptions& options, const io::ScenarioResolvers& resolvers);
CLI::App* add_lqr_subcommand(CLI::App& app, LqrOptions& options);

struct ParamsOptions {
  std::string controller{controllers::kDefaultControllerType};  ///< the controller type whose parameters are listed
  bool list = false;                                            ///< list the controller types instead
  bool vehicle = false;   ///< the vehicle's parameters instead of the controller's
  bool markdown = false;  ///< the vehicle table as Markdown (docs/model.md)
  std::string preset;     ///< with `vehicle`: the values of this ready vehicle (model/vehicle_presets.hpp)
};
/// Lists the controller's (or with `vehicle`, the vehicle's) parameters: name, unit, range, default,
/// meaning.
int params_command(const ParamsOptions& options, const io::ScenarioResolvers& resolvers);
CLI::App* add_params_subcommand(CLI::App& app, ParamsOptions& options);

/// Checks a --controller value as io::parse_controller_choice reads it (a registered type,
/// python:MODULE:CLASS or fmu:PATH); a refused value's message is the parser's.
void check_controller_choice(CLI::Option& option);

struct SummaryOptions {
  std::vector<std::string> run_dirs;
  std::string out;  ///< markdown file, "" for stdout only
};
int summary_command(const SummaryOptions& options);
CLI::App* add_summary_subcommand(CLI::App& app, SummaryOptions& options);

/// --vehicles N: how `plant` and `controller` host a swarm (lockstep only).
using NodeSwarmOptions = hosts::NodeSwarmOptions;

/// `quadcosim plant`: the plant process's options (hosts/node_options.hpp).
using PlantCommandOptions = hosts::PlantProcessOptions;
int plant_command(const PlantCommandOptions& options, const io::ScenarioResolvers& resolvers);
CLI::App* add_plant_subcommand(CLI::App& app, PlantCommandOptions& options);

/// `quadcosim controller`: the controller process's options (hosts/node_options.hpp).
using ControllerCommandOptions = hosts::ControllerProcessOptions;
int controller_command(const ControllerCommandOptions& options, const io::ScenarioResolvers& resolvers);
CLI::App* add_controller_subcommand(CLI::App& app, ControllerCommandOptions& options);

/// `quadcosim param get|set|list|describe NODE [NAME [VALUE]]` (param_command.cpp): the ROS 2
/// parameter services of a node over DDS, printed as `ros2 param` prints them. Exit 0 on success,
/// 1 when the node refuses a set or lacks the parameter, 2 on bad input, 4 when the node is not
/// found or does not answer within timeout_s.
struct ParamOptions {
  std::string verb;                   ///< "get", "set", "list" or "describe" (set by the subcommand parsed)
  std::string node;                   ///< "/attitude_controller" or "attitude_controller"
  std::string name;                   ///< the parameter (get, set, describe)
  std::string value;                  ///< set: read as `ros2 param set` reads it (10 integer, 10.0 double, ...)
  std::vector<std::string> prefixes;  ///< list: only names under these prefixes
  double timeout_s = 5.0;             ///< how long to look for the node and wait for its answer
  std::string enclave = "/";          ///< DDS Security enclave (rcl --enclave)
};
/// Adds the `param` subcommand with get/set/list/describe under `app`, parsing into `options`.
CLI::App* add_param_subcommand(CLI::App& app, ParamOptions& options);
int param_command(const ParamOptions& options);
/// "" when `text` is a valid ROS node name (NAME or /NAMESPACE/NAME), else why not (a CLI check).
std::string check_node_name(const std::string& text);

/// `quadcosim topic list|echo|hz`: the topic tools' options (hosts/topic_process.hpp).
using TopicOptions = hosts::TopicToolOptions;
/// Adds the `topic` subcommand with list/echo/hz under `app`, parsing into `options`.
CLI::App* add_topic_subcommand(CLI::App& app, TopicOptions& options);
int topic_command(TopicOptions options);

/// `quadcosim record`: the recorder process's options (hosts/recorder_process.hpp).
using RecordOptions = hosts::RecorderOptions;
int record_command(const RecordOptions& options);
CLI::App* add_record_subcommand(CLI::App& app, RecordOptions& options);

/// `quadcosim security create-keystore|create-enclave|check` (security_command.cpp). Exit 0 on
/// success, 1 when check finds problems, 2 on bad input (an existing keystore, a bad name or topic).
struct SecurityOptions {
  std::string verb;                       ///< set by the subcommand parsed
  std::string dir;                        ///< the keystore
  std::string name;                       ///< the enclave (create-enclave, check)
  std::vector<std::string> deny_publish;  ///< create-enclave: ROS topics the enclave may not publish
  bool read_only = false;                 ///< create-enclave: subscribe only
  int domain_id = -1;                     ///< < 0: ROS_DOMAIN_ID (or 0), as sros2 does
};
CLI::App* add_security_subcommand(CLI::App& app, SecurityOptions& options);
int security_command(const SecurityOptions& options);

/// Adds `--controller TYPE` (a registered controller type, checked) to `cmd`.
void add_controller_type_option(CLI::App& cmd, std::string& type);

/// `--judge spec|paper|none` (run, sweep): the criteria set a run is judged against (io::Judge); any
/// other value is refused (exit 2) with the choices.
void add_judge_option(CLI::App& cmd, std::string& judge);

/// Adds `--enclave NAME` (validated as rcl validates enclave names) to a DDS command.
void add_enclave_option(CLI::App* command, std::string& enclave);
/// `--cpus LIST` (plant, controller): the CPUs the process runs on, checked as a CPU list.
void add_cpus_option(CLI::App* command, std::string& cpus);
/// The flags with which `plant` and `controller` host their vehicles: --namespace (one vehicle),
/// --vehicles, --ns-prefix, --threads (a swarm), --sensor-qos (`sensor_qos_help` says which way) and --cpus.
void add_node_host_options(CLI::App* command, std::string& ns, NodeSwarmOptions& swarm, bool& sensor_qos,
                           const std::string& sensor_qos_help, std::string& cpus);

/// One row of a command's table of flags that act in some modes only: `flag` acts when `acts` holds;
/// when it does not, `mode` names the mode chosen and what the flag needs ("lockstep; it needs --realtime").
struct FlagRule {
  const char* flag;
  bool acts;
  const char* mode;
};
/// Refuses a flag that would do nothing: throws CLI::ValidationError "FLAG: does nothing with MODE" (exit 2)
/// for the first rule whose flag was given to `command` and does not act. Call it from the command's
/// parse_complete_callback, once every flag is parsed and before anything runs.
void refuse_idle_flags(const CLI::App& command, std::initializer_list<FlagRule> rules);
/// `quadcosim sweep` (sweep_command.cpp, on the sweep library src/sweep/, docs/sweeps.md): runs of a
/// scenario with varied keys and seeded noise; `sweep rerun DIR I --out RUN` flies run I again with
/// the outputs of `run`; `sweep merge OUT DIR...` joins shards. Exit 0 when at least min_pass_rate of
/// the runs pass (a shard: when it ran), 1 otherwise, 2 on bad input, 3 when an output cannot be written.
struct SweepOptions {
  std::string mode = "sweep";  ///< "sweep", "rerun" or "merge"
  std::string scenario;
  int runs = 20;  ///< runs, or runs per grid point with a grid (default 1 then)
  bool runs_given = false;
  std::uint64_t seed = 1;
  std::vector<std::string> vary;   ///< KEY=P%, KEY=uniform(a,b), ... (sweep/plan.hpp)
  std::string sampler = "random";  ///< random or lhs
  std::string keep = "none";       ///< trajectories kept: none, failing, all
  std::string shard;               ///< "K/N" or ""
  bool force = false;
  bool resume = false;  ///< finish the interrupted sweep in out_dir (its missing runs only)
  std::string out_dir;
  int jobs = 2;  ///< threads
  double min_pass_rate = 1.0;
  bool plots = true;
  bool progress = true;           ///< runs done, pass rate and time left on stderr while the runs go
  double progress_every_s = 5.0;  ///< seconds between progress lines when stderr is no terminal (0: each run)
  std::string sweep_dir;          ///< rerun: the sweep
  int rerun_index = 0;
  std::vector<std::string> shard_dirs;  ///< merge: the shards
  std::string judge = "spec";           ///< --judge: spec, paper or none (as `run`'s)
};
CLI::App* add_sweep_subcommand(CLI::App& app, SweepOptions& options);
int sweep_command(const SweepOptions& options, const io::ScenarioResolvers& resolvers);

/// `quadcosim margins [SCENARIO]` (margins_command.cpp, docs/margins.md): gain, phase and delay margins
/// of each loop about hover: analytic for the paper controller, measured in simulation for any
/// controller (and for the paper's too with --measure). Exit 0 when every loop is stable closed-loop
/// (measured: every loop stayed in hover), 1 when one is not (its margins are undefined), 2 on bad
/// input (file, flag, a vehicle that cannot hover, an LQR design that fails), 3 when an output cannot
/// be written, 5 when the controller's step fails.
struct MarginsOptions {
  std::string scenario;        ///< "" for the defaults
  std::string controller;      ///< --controller: replaces the scenario's controller.type ("" keeps it)
  std::string out_dir;         ///< "" for stdout only
  bool force = false;          ///< replace a previous command's outputs in out_dir
  bool json = false;           ///< print JSON instead of the table
  bool plots = true;           ///< with out_dir: Bode and Nyquist PNGs (tools/plot_margins.py)
  bool measure = false;        ///< the paper controller: measure too (other controllers are always measured)
  double amplitude = 1e-4;     ///< measured: injection, fraction of the hover rotor speed
  int frequencies = 24;        ///< measured: log-spaced grid frequencies up to Nyquist
  double min_frequency = 0.1;  ///< measured: lowest grid frequency [rad/s]
};
CLI::App* add_margins_subcommand(CLI::App& app, MarginsOptions& options);
int margins_command(const MarginsOptions& options, const io::ScenarioResolvers& resolvers);

/// `quadcosim fmu export|info` (fmu_command.cpp): quadcosim's plant or controller as an FMI co-simulation
/// FMU, and what any FMU declares. Exit 0 on success, 2 on bad input (a flag, the scenario, a file
/// that is not an FMU), 3 when the FMU cannot be written or the FMU library is not found.
struct FmuOptions {
  std::string verb;        ///< "export" or "info" (set by the subcommand parsed)
  std::string kind;        ///< export: "plant" or "controller"
  std::string scenario;    ///< export: "" for the defaults (the paper's vehicle and controller)
  std::string controller;  ///< export --controller: replaces the scenario's controller.type ("" keeps it)
  int fmi = 2;             ///< export: FMI version, 2 or 3
  std::string out;         ///< export: the .fmu to write
  std::string fmu;         ///< info: the .fmu to read
};
CLI::App* add_fmu_subcommand(CLI::App& app, FmuOptions& options);
int fmu_command(const FmuOptions& options, const io::ScenarioResolvers& resolvers);

/// Runs tools/`script` with `args` under /usr/bin/python3 (QUADCOSIM_PYTHON, QUADCOSIM_TOOLS_DIR
/// override); returns false (after printing why) when it fails.
bool run_tool(const std::string& script, const std::vector<std::string>& args);

/// `quadcosim plot RUN_DIR`: regenerates the figures and report.html of a run, removing those a previous
/// plot wrote there first (the "figures" of the folder's manifest, io/output_folder.hpp).
struct PlotOptions {
  std::string run_dir;
};
CLI::App* add_plot_subcommand(CLI::App& app, PlotOptions& options);
int plot_command(const PlotOptions& options);

/// `quadcosim compare RUN_A RUN_B [--out DIR]`: overlays two runs and tabulates their step figures.
struct CompareOptions {
  std::string run_a, run_b;
  std::string out;     ///< "" for RUN_B/compare_with_<RUN_A>
  bool force = false;  ///< write into a folder holding other files or outputs (a previous compare's are replaced)
};
CLI::App* add_compare_subcommand(CLI::App& app, CompareOptions& options);
int compare_command(const CompareOptions& options);

using BenchOptions = hosts::BenchOptions;
/// `quadcosim bench`: speed figures of this machine (bench_command.cpp, docs/performance.md).
int bench_command(const BenchOptions& options, const io::ScenarioResolvers& resolvers);
CLI::App* add_bench_subcommand(CLI::App& app, BenchOptions& options);

/// The PNG plots and report.html of a run directory (tools/plot_run.py, tools/report.py). The files
/// written before are recorded in `folder` as its "outputs", the plots and report as its "figures"
/// (what `plot` replaces).
bool make_plots(const std::string& run_dir, io::OutputFolder& folder);

}  // namespace quadcosim::app
