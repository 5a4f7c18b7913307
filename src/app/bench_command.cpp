// `quadcosim bench [--json] [--quick]`: the framework's speed on this machine, measured end to end
// (docs/performance.md; the figures and how each is measured: hosts/bench.hpp). Prints figures;
// asserts nothing. This file reads the flags, describes the machine and prints.
#include <fmt/format.h>
#include <sys/utsname.h>
#include <CLI/CLI.hpp>

#include <cmath>
#include <fstream>
#include <iostream>
#include <nlohmann/json.hpp>
#include <string>
#include <thread>

#include "app/commands.hpp"
#include "app/exit_codes.hpp"
#include "app/resources.hpp"
#include "hosts/bench.hpp"

namespace quadcosim::app {

namespace {

// The machine the figures were measured on.
nlohmann::json machine() {
  std::string cpu = "unknown";
  std::ifstream f("/proc/cpuinfo");
  for (std::string line; std::getline(f, line);) {
    if (line.rfind("model name", 0) == 0) {
      cpu = line.substr(line.find(':') + 2);
      break;
    }
  }
  utsname u{};
  uname(&u);
  return {{"cpu_model", cpu},
          {"cores", std::thread::hardware_concurrency()},
          {"kernel", fmt::format("{} {} {}", u.sysname, u.release, u.machine)},
          {"compiler", fmt::format("{} {}", QUADCOSIM_COMPILER_ID, __VERSION__)},
          {"build_type", QUADCOSIM_BUILD_TYPE},
          {"load_average_1min", [] {
             double l = NAN;
             std::ifstream("/proc/loadavg") >> l;
             return l;
           }()}};
}

}  // namespace

CLI::App* add_bench_subcommand(CLI::App& app, BenchOptions& bench) {
  bench.scenario = (scenarios_dir() / "paper" / "altitude_step.yaml").string();
  bench.swarm_scenario = (scenarios_dir() / "swarm" / "grid_takeoff.yaml").string();
  auto* bench_cmd = app.add_subcommand("bench", "measure speed: in-process, DDS lockstep, real-time jitter, swarms");
  bench_cmd->add_flag("--json", bench.json, "print one JSON object");
  bench_cmd->add_flag("--quick", bench.quick, "short runs (smoke test; the figures are not representative)");
  bench_cmd->add_option("--only", bench.only, "run one part")
      ->check(CLI::IsMember({"inproc", "dds", "realtime", "swarm_inproc", "swarm_dds"}));
  bench_cmd->add_option("--seconds", bench.seconds, "simulated seconds of the inproc/dds part")
      ->check(CLI::Range(0.0, 1e6));
  bench_cmd
      ->add_option("--rt-priority", bench.rt_priority, "realtime part: SCHED_FIFO priority of the controller (0: skip)")
      ->check(CLI::Range(0, 99));
  bench_cmd->add_option("--scenario", bench.scenario, "single-vehicle scenario")->check(CLI::ExistingFile);
  bench_cmd->add_option("--swarm-scenario", bench.swarm_scenario, "swarm scenario")->check(CLI::ExistingFile);
  return bench_cmd;
}

int bench_command(const BenchOptions& o, const io::ScenarioResolvers& resolvers) {
  nlohmann::json j = hosts::run_bench(o, resolvers);
  j["machine"] = machine();
  if (o.json) {
    std::cout << j.dump() << std::endl;
  } else {
    std::cout << j.dump(2) << std::endl;
  }
  return exit_code::kOk;
}

}  // namespace quadcosim::app
