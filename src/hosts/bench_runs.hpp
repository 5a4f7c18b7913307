// What `quadcosim bench` measures by running things (bench_runs.cpp; the command is app/bench_command.cpp,
// docs/performance.md).
#pragma once

#include <chrono>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <string>

#include "io/scenario.hpp"

namespace quadcosim::hosts {

/// Wall-clock seconds from `t0` to now.
double seconds_since(std::chrono::steady_clock::time_point t0);

/// One vehicle in-process (any controller) for sim_s simulated seconds, recording off [x real time].
double inproc_rtf(const io::Scenario& sc, double sim_s);

/// In-process swarm of n vehicles for sim_s [x real time].
double swarm_inproc_rtf(const io::Scenario& sc, int n, double sim_s);

/// Plant and controller processes over DDS (lockstep, or real time); the plant's --stats (and the
/// controller's, in real time) as JSON; null on failure.
struct NodeRun {
  nlohmann::json plant, controller;
};
/// Runs them for sim_s simulated seconds (`vehicles` > 0: a swarm of that many) from this executable,
/// their logs in `tmp`; real time with the controller at `rt_priority` (0: normal scheduling), or
/// lockstep; `pinned`: each on its own CPU.
NodeRun run_nodes(const std::filesystem::path& tmp, const std::string& scenario, double sim_s, int vehicles,
                  bool realtime, int rt_priority = 0, bool pinned = false);

}  // namespace quadcosim::hosts
