// A swarm in one process as library functions (sim::Swarm recorded and judged), so that every front
// end that flies a swarm in process (`quadcosim run`, the Python module) writes the same bytes: each
// recorded vehicle's <ns>/trajectory.csv, metrics.json and metrics.txt, vehicles.csv and summary.json
// (docs/outputs.md, "A swarm run").
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <filesystem>
#include <functional>
#include <nlohmann/json.hpp>
#include <optional>
#include <ostream>
#include <string>
#include <vector>

#include "io/scenario.hpp"
#include "io/step_report.hpp"

namespace quadcosim::hosts {

/// In-process swarms advance each vehicle 100 ticks (1 s at 100 Hz) at a time (sim::Swarm::run).
constexpr sim::Tick kSwarmBlockTicks = 100;

/// The scenario's swarm section (defaults when it has none) with --vehicles / --threads applied
/// (values <= 0 leave the scenario's); recorded vehicles beyond N are dropped.
io::SwarmSpec swarm_spec(const io::Scenario& sc, int vehicles, int threads);

/// Creates the folder of each recorded vehicle of `spec` in `out` ("uav0003" for /uav0003) with
/// `scenario_yaml` (the scenario as flown) as its scenario.yaml; returns the folder names in the order of
/// spec.record_vehicles.
std::vector<std::string> make_recorded_dirs(const std::filesystem::path& out, const io::SwarmSpec& spec,
                                            const std::string& scenario_yaml);

/// One vehicle at the end of a swarm run.
struct SwarmFinal {
  Eigen::Vector3d p_W = Eigen::Vector3d::Zero();      ///< final position [m]
  Eigen::Vector3d p_des_W = Eigen::Vector3d::Zero();  ///< its setpoint [m]
  bool safety = false;                                ///< its last command was the safety command
  std::uint64_t rejected = 0;                         ///< motor commands its plant rejected
};

/// Writes out/summary.json (run_figures + layout + error spread) and out/vehicles.csv; the one-line
/// spread to `info`.
void write_swarm_summary(const std::filesystem::path& out, const io::Scenario& sc, const io::SwarmSpec& spec,
                         const std::vector<std::string>& namespaces, const std::vector<SwarmFinal>& rows,
                         const nlohmann::json& run_figures, std::ostream& info);

/// Flies the swarm `spec` of `scenario` in this process (sim::Swarm on spec.threads threads) into `out`,
/// where the recorded vehicles' folders exist: their trajectory.csv, then vehicles.csv and summary.json
/// (without verdicts: judge_swarm adds them). `on_block`, when set, is called with the simulated time
/// [s] after each block of kSwarmBlockTicks ticks the calling thread flies (on that thread); when it
/// returns true the run stops there (the recorded
/// ticks stay in the CSVs, no summary is written) and fly_swarm_inprocess returns false. Throws as
/// sim::Swarm does (a refused scheduled parameter: std::invalid_argument), std::runtime_error on I/O.
bool fly_swarm_inprocess(const io::Scenario& scenario, const io::SwarmSpec& spec, const std::filesystem::path& out,
                         std::ostream& info, const std::function<bool(double t_s)>& on_block = {});

/// The verdicts of a swarm run.
struct SwarmJudgement {
  /// One entry per recorded vehicle: vehicle, namespace, passed (null under Judge::kNone),
  /// saturation figures; as summary.json "recorded".
  nlohmann::json recorded = nlohmann::json::array();
  bool passed = true;  ///< no recorded vehicle failed a judged criterion: `run` exits 1 exactly when false
  std::vector<std::string> warnings;  ///< saturation warnings, "uav0000: ..." each
};

/// Judges each recorded vehicle from its <dir>/trajectory.csv as `run` judges one vehicle (its
/// metrics.json with `provenance`, metrics.txt) and adds "recorded" and "provenance" to summary.json.
/// Throws std::runtime_error on I/O.
SwarmJudgement judge_swarm(const io::Scenario& scenario, const io::SwarmSpec& spec, const std::filesystem::path& out,
                           io::Judge judge, const nlohmann::json& provenance);

}  // namespace quadcosim::hosts
