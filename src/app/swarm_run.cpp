// `quadcosim run SCENARIO --vehicles N` (or a scenario with a `swarm:` section): many vehicles,
// in-process (sim::Swarm) or over DDS (one plant and one controller process hosting all vehicles).
// What a swarm run writes (docs/outputs.md): summary.json (run figures, the spread of the final
// tracking errors, the recorded vehicles' verdicts and saturation figures), vehicles.csv (one row per
// vehicle: final state, setpoint, error, safety), and a full <ns>/trajectory.csv (+ metrics) only for
// the vehicles listed in swarm.record_vehicles.
#include <fmt/format.h>

#include <filesystem>
#include <iostream>
#include <nlohmann/json.hpp>

#include "app/commands.hpp"
#include "app/exit_codes.hpp"
#include "app/swarm.hpp"
#include "hosts/child_process.hpp"
#include "hosts/node_common.hpp"
#include "hosts/signals.hpp"
#include "io/output_folder.hpp"
#include "io/provenance.hpp"

namespace quadcosim::app {

namespace fs = std::filesystem;

int run_swarm(const RunOptions& opt, const io::Scenario& sc, const fs::path& out, io::OutputFolder& folder,
              const nlohmann::json& provenance) {
  const io::SwarmSpec spec = hosts::swarm_spec(sc, opt.vehicles, opt.threads);
  const int n = spec.layout.vehicles;
  const std::vector<std::string> dirs =
      hosts::make_recorded_dirs(out, spec, io::effective_scenario_text(opt.scenario, opt.controller));
  hosts::install_stop_handlers();
  if (opt.transport == "dds") {
    // The plant process records; the controller process answers.
    const std::string self = hosts::self_executable();
    std::vector<std::string> plant_args = {
        self,          "plant",           "--scenario", opt.scenario,
        "--vehicles",  std::to_string(n), "--timeout",  fmt::format("{}", opt.timeout_s),
        "--swarm-out", out.string()};
    std::vector<std::string> controller_args = {self,         "controller", "--scenario",
                                                opt.scenario, "--vehicles", std::to_string(n)};
    if (!opt.controller.empty()) {
      controller_args.push_back("--controller");
      controller_args.push_back(opt.controller);
    }
    if (opt.pin) hosts::pin_apart(plant_args, controller_args);
    if (const int rc = hosts::run_plant_and_controller(plant_args, controller_args); rc != 0) return rc;
  } else if (!hosts::fly_swarm_inprocess(sc, spec, out, std::cout, [](double) { return hosts::stop_requested(); })) {
    std::cerr << "\nrun: interrupted; the recorded vehicles' trajectory.csv hold what ran\n";
    return exit_code::kInterrupted;
  }
  const hosts::SwarmJudgement judged =
      hosts::judge_swarm(sc, spec, out, io::parse_judge(opt.judge).value_or(io::Judge::kSpec), provenance);
  for (const std::string& w : judged.warnings) std::cerr << "run: " << w << '\n';
  std::cout << "wrote " << (out / "summary.json").string() << ", vehicles.csv"
            << (dirs.empty() ? "" : fmt::format(", {} recorded vehicle(s)", dirs.size())) << '\n';
  if (opt.plots) {
    for (const std::string& d : dirs) {
      if (!make_plots((out / d).string(), folder)) return exit_code::kOutput;
    }
  }
  return judged.passed ? exit_code::kOk : exit_code::kFailed;
}

}  // namespace quadcosim::app
