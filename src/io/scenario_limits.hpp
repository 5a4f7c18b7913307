// Sane limits on what a scenario, an FMU or a command line may ask for: past them a run would only
// exhaust the memory or the disk (a schedule of millions of entries, a plant at a megahertz, a
// duration whose outputs outgrow the disk). Each refusal is a ConfigError (exit 2) naming the key,
// the value and the limit, and how to raise it. A user who really wants more says so on the command
// line (`--limit NAME=VALUE`, `--no-limits`), never a scenario file: a file from elsewhere cannot lift
// its own limits. docs/scenarios.md lists them.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "fmi/unzip.hpp"

namespace quadcosim::io {

struct Limits {
  bool enabled = true;                        ///< false: --no-limits (every check below is off)
  std::uint64_t scenario_bytes = 2ULL << 20;  ///< a YAML file's size (scenario, vehicle, controller) [bytes]
  std::uint64_t schedule_entries = 20'000;    ///< parameter changes in a scenario's schedule
  double plant_rate_hz = 10'000.0;            ///< simulation.plant_rate_hz [Hz]
  fmi::FmuLimits fmu;                         ///< fmu_entries, fmu_unpacked_bytes, fmu_variables
  /// Refuse a run whose projected outputs exceed the free space of its output folder (no number:
  /// the projection is checked against the disk; --no-limits turns it off).
  bool check_disk = true;
  /// Refuse a swarm whose projected memory exceeds the memory available (MemAvailable).
  bool check_memory = true;
};

/// The names `--limit` takes, in the order docs/scenarios.md lists them.
const std::vector<std::string>& limit_names();

/// The limits in force in this process (the defaults unless the command line changed them).
const Limits& limits();
/// Sets them, and the FMU limits (fmi::set_fmu_limits): once, by the command line, before any file is
/// read and before any thread starts.
void set_limits(const Limits& limits);

/// Applies one `--limit NAME=VALUE` to `l`; returns "" or what is wrong (an unknown name, lists the
/// known ones; a value that is not a positive number).
std::string apply_limit(Limits& l, const std::string& assignment);

/// The tail of every refusal: "limit NAME; raise it with --limit NAME=N, or --no-limits".
using fmi::limit_hint;

/// Free bytes of the file system holding `folder` (its nearest existing ancestor); -1 when unknown
/// (also for a file system without blocks, such as /proc).
long long free_disk_bytes(const std::string& folder);
/// MemAvailable of /proc/meminfo [bytes]; -1 when unknown.
long long available_memory_bytes();

/// Bytes a run writes per plant tick and per controller step, measured (docs/performance.md):
/// trajectory.csv's row and run.mcap's compressed messages of a tick (with /tf) and of a step.
inline constexpr double kOutputBytesPerPlantTick = 1000.0;
inline constexpr double kOutputBytesPerControlStep = 150.0;

/// Refuses (ConfigError) a run of `plant_ticks` plant ticks and `control_steps` controller steps whose
/// projected outputs exceed the free space of `folder`, naming both; `what` names the run ("run",
/// "plant --record"). Does nothing with limits().check_disk off or limits() disabled.
void check_output_fits(const std::string& what, const std::string& folder, double plant_ticks, double control_steps);

/// Resident memory a swarm vehicle costs in an in-process run, measured (docs/performance.md) [bytes].
inline constexpr double kSwarmBytesPerVehicle = 18'000.0;

/// Refuses (ConfigError) a swarm of `vehicles` whose projected memory exceeds MemAvailable, naming
/// both. Does nothing with limits().check_memory off or limits() disabled.
void check_swarm_fits(int vehicles);

/// The command-line arguments (--no-limits, --limit NAME=VALUE) that set `l` in a child process.
std::vector<std::string> limit_arguments(const Limits& l);

}  // namespace quadcosim::io
