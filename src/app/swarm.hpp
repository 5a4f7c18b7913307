// Swarm runs: many vehicles in one `run`, in-process or over DDS (swarm_run.cpp; the hosts are
// hosts/swarm_inprocess.hpp and hosts/swarm_nodes.hpp).
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "app/commands.hpp"
#include "hosts/swarm_inprocess.hpp"
#include "io/scenario.hpp"

namespace quadcosim::app {

/// `run` for a swarm into `out`, the folder `folder` has claimed: exit codes as `run` (0 all recorded
/// vehicles pass their step criteria and the scenario's analysis.limits); adds "recorded" (each
/// recorded vehicle's verdict and saturation figures) and `provenance` (the run's io::describe_run
/// record, also in each recorded vehicle's metrics.json) to summary.json.
int run_swarm(const RunOptions& options, const io::Scenario& sc, const std::filesystem::path& out,
              io::OutputFolder& folder, const nlohmann::json& provenance);

}  // namespace quadcosim::app
