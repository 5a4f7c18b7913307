// `quadcosim bench` (docs/performance.md): the framework's speed on this machine, measured end to end;
// the parts it runs are bench_runs.hpp's. Figures only; it asserts nothing.
//   inproc_rtf                 one vehicle in-process (paper altitude scenario, recording off)
//   baseline_rtf               the BASELINE minimal loop (bench/baseline/baseline_loop.hpp) on the same
//                              vehicle and gains: the machine's floor for this model
//   dds_lockstep_rtf, dds_cmd_roundtrip_us_p50/p99
//                              plant and controller as two processes over DDS, lockstep
//   ddsperf_roundtrip_us_p50   Cyclone's own ddsperf ping/pong (when ddsperf is installed)
//   realtime_period_jitter_us_p99
//                              the controller's 50 Hz loop in real time (plant in real time too)
//   swarm_inproc_vehicles_at_rt, swarm_dds_vehicles_at_rt
//                              the largest swarm found at >= 1x real time (doubling, then bisection)
//   *_pinned                   the DDS figures again with the plant and the controller each on its
//                              own CPU (--cpus; pinned_cpus names them, null with fewer than 2 CPUs)
#pragma once

#include <nlohmann/json.hpp>
#include <string>

#include "io/scenario_resolvers.hpp"

namespace quadcosim::hosts {

struct BenchOptions {
  bool json = false;           ///< one JSON object on stdout (else the same, indented)
  bool quick = false;          ///< short runs and small searches (a smoke test, not figures)
  std::string only;            ///< one part: inproc, dds, realtime, swarm_inproc, swarm_dds ("" all)
  double seconds = 0.0;        ///< > 0: simulated seconds of the inproc / dds part (e.g. for callgrind)
  std::string scenario;        ///< single-vehicle scenario (default: scenarios/paper/altitude_step.yaml)
  std::string swarm_scenario;  ///< swarm scenario (default: scenarios/swarm/grid_takeoff.yaml)
  int rt_priority = 50;        ///< realtime part: also measure with the controller under SCHED_FIFO (0: not)
};

/// Runs the parts `o` asks for and returns their figures (the keys above, and quick and bench_wall_s),
/// saying on stderr what it measures as it goes. Throws io::ConfigError for a bad scenario.
nlohmann::json run_bench(const BenchOptions& o, const io::ScenarioResolvers& resolvers);

}  // namespace quadcosim::hosts
