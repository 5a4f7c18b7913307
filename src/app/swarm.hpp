// Swarm runs: many vehicles in one `run`, in-process or over DDS (swarm_run.cpp, swarm_nodes.cpp).
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "app/commands.hpp"
#include "io/scenario.hpp"

namespace quadcosim::app {

/// In-process swarms advance each vehicle 100 ticks (1 s at 100 Hz) at a time (sim::Swarm::run).
constexpr sim::Tick kSwarmBlockTicks = 100;

/// The scenario's swarm section (defaults when it has none) with --vehicles / --threads applied
/// (values <= 0 leave the scenario's); recorded vehicles beyond N are dropped.
io::SwarmSpec swarm_spec(const io::Scenario& sc, int vehicles, int threads);

/// One vehicle at the end of a swarm run.
struct SwarmFinal {
  Eigen::Vector3d p_W = Eigen::Vector3d::Zero();      ///< final position [m]
  Eigen::Vector3d p_des_W = Eigen::Vector3d::Zero();  ///< its setpoint [m]
  bool safety = false;                                ///< its last command was the safety command
  std::uint64_t rejected = 0;                         ///< motor commands its plant rejected
};

/// Writes out/summary.json (run_figures + layout + error spread) and out/vehicles.csv.
void write_swarm_summary(const std::filesystem::path& out, const io::Scenario& sc, const io::SwarmSpec& spec,
                         const std::vector<std::string>& namespaces, const std::vector<SwarmFinal>& rows,
                         const nlohmann::json& run_figures);

/// `run` for a swarm into `out`, the folder `folder` has claimed: exit codes as `run` (0 all recorded
/// vehicles pass their step criteria and the scenario's analysis.limits); adds "recorded" (each
/// recorded vehicle's verdict and saturation figures) and `provenance` (the run's io::describe_run
/// record, also in each recorded vehicle's metrics.json) to summary.json.
int run_swarm(const RunOptions& options, const io::Scenario& sc, const std::filesystem::path& out,
              io::OutputFolder& folder, const nlohmann::json& provenance);

/// `plant --vehicles N` / `controller --vehicles N`: N vehicles in one process over DDS.
int swarm_plant_command(const PlantCommandOptions& options, io::Scenario sc);
int swarm_controller_command(const ControllerCommandOptions& options, io::Scenario sc);

}  // namespace quadcosim::app
