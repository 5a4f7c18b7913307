// What `quadcosim bench` measures by running things: one vehicle and a swarm in process, plant and
// controller as two processes over DDS.
#include "hosts/bench_runs.hpp"

#include <fmt/format.h>

#include <chrono>
#include <filesystem>
#include <fstream>
#include <iostream>

#include "hosts/child_process.hpp"
#include "hosts/node_common.hpp"
#include "hosts/swarm_inprocess.hpp"
#include "sim/simulation.hpp"
#include "sim/swarm.hpp"

namespace quadcosim::hosts {

namespace fs = std::filesystem;

double seconds_since(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

namespace {

nlohmann::json read_json(const fs::path& p) {
  std::ifstream f(p);
  if (!f) return nullptr;
  try {
    return nlohmann::json::parse(f);
  } catch (const std::exception&) {
    return nullptr;
  }
}

}  // namespace

double inproc_rtf(const io::Scenario& sc, double sim_s) {
  sim::SimulationConfig cfg = sc.simulation;
  cfg.duration_ticks = static_cast<sim::Tick>(sim_s / cfg.plant.clock.period_s() + 0.5);
  sim::Simulation s(cfg, sc.vehicle, io::initial_state(sc), sc.controller, sc.schedule);
  const auto t0 = std::chrono::steady_clock::now();
  for (sim::Tick k = 0; k <= cfg.duration_ticks; ++k) s.tick(k);
  return sim_s / seconds_since(t0);
}

double swarm_inproc_rtf(const io::Scenario& sc, int n, double sim_s) {
  io::SwarmSpec spec = swarm_spec(sc, n, 2);
  sim::SimulationConfig cfg = sc.simulation;
  cfg.duration_ticks = static_cast<sim::Tick>(sim_s / cfg.plant.clock.period_s() + 0.5);
  sim::Swarm swarm(cfg, sc.vehicle, io::initial_state(sc), sc.controller, sc.schedule, spec.layout);
  const auto t0 = std::chrono::steady_clock::now();
  swarm.run(spec.threads, kSwarmBlockTicks);
  return sim_s / seconds_since(t0);
}

NodeRun run_nodes(const fs::path& tmp, const std::string& scenario, double sim_s, int vehicles, bool realtime,
                  int rt_priority, bool pinned) {
  const std::string self = self_executable();
  const std::string ps = (tmp / "plant.json").string(), cs = (tmp / "controller.json").string();
  fs::remove(ps);
  fs::remove(cs);
  std::vector<std::string> c = {self, "controller", "--scenario", scenario};
  std::vector<std::string> p = {self,      "plant", "--scenario", scenario, "--duration", fmt::format("{}", sim_s),
                                "--stats", ps,      "--timeout",  "60"};
  if (vehicles > 0) {
    for (auto* v : {&c, &p}) {
      v->push_back("--vehicles");
      v->push_back(std::to_string(vehicles));
    }
  }
  if (pinned) pin_apart(p, c);
  if (realtime) {
    // The controller's --stats (its period jitter) is real time only.
    for (const std::string& a : {std::string("--realtime"), std::string("--stats"), cs}) c.push_back(a);
    if (rt_priority > 0) {
      c.push_back("--rt-priority");
      c.push_back(std::to_string(rt_priority));
    }
    p.push_back("--realtime");
    p.push_back("--wait-for-controller");
  }
  NodeRun out;
  {
    ChildProcess controller(c, (tmp / "controller.log").string());
    ChildProcess plant(p, (tmp / "plant.log").string());
    const auto rc = plant.wait(600.0);
    controller.stop();
    if (!rc || *rc != 0) {
      std::cerr << "bench: "
                << fmt::format("plant exited with {} (log: {})", rc ? *rc : -1, (tmp / "plant.log").string())
                << std::endl;
      return out;
    }
  }
  out.plant = read_json(ps);
  out.controller = read_json(cs);
  return out;
}

}  // namespace quadcosim::hosts
