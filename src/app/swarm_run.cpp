// `quadcosim run SCENARIO --vehicles N` (or a scenario with a `swarm:` section): many vehicles,
// in-process (sim::Swarm) or over DDS (one plant and one controller process hosting all vehicles).
// What a swarm run writes (docs/outputs.md): summary.json (run figures, the spread of the final
// tracking errors, the recorded vehicles' verdicts and saturation figures), vehicles.csv (one row per
// vehicle: final state, setpoint, error, safety), and a full <ns>/trajectory.csv (+ metrics) only for
// the vehicles listed in swarm.record_vehicles.
#include <fmt/format.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <memory>
#include <nlohmann/json.hpp>

#include "analysis/percentile.hpp"
#include "app/child_process.hpp"
#include "app/commands.hpp"
#include "app/exit_codes.hpp"
#include "app/node_common.hpp"
#include "app/signals.hpp"
#include "app/swarm.hpp"
#include "io/output_folder.hpp"
#include "io/provenance.hpp"
#include "io/step_report.hpp"
#include "io/trajectory_csv.hpp"

namespace quadcosim::app {

namespace fs = std::filesystem;

io::SwarmSpec swarm_spec(const io::Scenario& sc, int vehicles, int threads) {
  io::SwarmSpec spec = sc.swarm.value_or(io::SwarmSpec{});
  if (vehicles > 0) spec.layout.vehicles = vehicles;
  if (threads > 0) spec.threads = threads;
  std::erase_if(spec.record_vehicles, [&](int i) { return i >= spec.layout.vehicles; });
  return spec;
}

namespace {

// Step figures and saturation (analysis.limits) of each recorded vehicle, judged from its trajectory.csv as
// `run` judges a single vehicle: writes its metrics.json and metrics.txt, warns when it saturated. Returns
// one entry per vehicle for summary.json: vehicle, namespace, passed, saturation figures.
nlohmann::json judge_recorded(const fs::path& out, const io::Scenario& sc, const std::vector<int>& vehicles,
                              const std::vector<std::string>& dirs, io::Judge judge, const nlohmann::json& provenance) {
  nlohmann::json entries = nlohmann::json::array();
  for (std::size_t i = 0; i < dirs.size(); ++i) {
    const fs::path dir = out / dirs[i];
    const io::Series series = io::read_series((dir / "trajectory.csv").string());
    const auto results = io::evaluate_steps(sc.steps, series, judge);
    const auto saturation = io::evaluate_saturation(sc, series, judge);
    const nlohmann::json metrics = io::metrics_json(sc, results, {}, saturation, {}, judge);
    io::write_metrics_with_provenance(dir / "metrics.json", metrics, provenance);
    std::ofstream((dir / "metrics.txt").string()) << io::format_step_table(sc, results, {}, saturation, {}, judge);
    if (saturation) {
      if (const std::string w = io::saturation_warning(*saturation); !w.empty()) {
        std::cerr << "run: " << dirs[i] << ": " << w << '\n';
      }
    }
    nlohmann::json e = {{"vehicle", vehicles[i]}, {"namespace", "/" + dirs[i]}, {"passed", metrics.at("passed")}};
    e["saturation"] = metrics.contains("saturation") ? metrics["saturation"]["figures"] : nlohmann::json();
    entries.push_back(e);
  }
  return entries;
}

std::string dir_of(const std::string& ns) { return ns.substr(1); }  // "/uav0003" -> "uav0003"

}  // namespace

void write_swarm_summary(const fs::path& out, const io::Scenario& sc, const io::SwarmSpec& spec,
                         const std::vector<std::string>& namespaces, const std::vector<SwarmFinal>& rows,
                         const nlohmann::json& run_figures) {
  std::ofstream csv(out / "vehicles.csv");
  csv << "index,namespace,x_m,y_m,z_m,x_des_m,y_des_m,z_des_m,error_m,safety,commands_rejected\n";
  std::vector<double> errors;
  errors.reserve(rows.size());
  int safety = 0, non_finite = 0;
  for (std::size_t i = 0; i < rows.size(); ++i) {
    const SwarmFinal& r = rows[i];
    const double e = (r.p_W - r.p_des_W).norm();
    errors.push_back(std::isfinite(e) ? e : INFINITY);
    safety += r.safety ? 1 : 0;
    non_finite += r.p_W.allFinite() ? 0 : 1;
    csv << fmt::format("{},{},{},{},{},{},{},{},{},{},{}\n", i, namespaces[i], r.p_W.x(), r.p_W.y(), r.p_W.z(),
                       r.p_des_W.x(), r.p_des_W.y(), r.p_des_W.z(), e, r.safety ? 1 : 0, r.rejected);
  }
  if (!csv) throw std::runtime_error("cannot write " + (out / "vehicles.csv").string());
  std::vector<double> sorted = errors;
  std::sort(sorted.begin(), sorted.end());
  auto pct = [&](double q) { return analysis::percentile_lower(sorted, q); };
  double mean = 0.0;
  for (double e : errors) mean += e / static_cast<double>(errors.size());
  nlohmann::json j = run_figures;
  j["scenario"] = sc.name;
  j["vehicles"] = spec.layout.vehicles;
  j["spacing_m"] = spec.layout.spacing_m;
  j["altitude_layers"] = spec.layout.altitude_layers;
  j["layer_spacing_m"] = spec.layout.layer_spacing_m;
  j["namespace_prefix"] = spec.layout.ns_prefix;
  j["simulated_s"] = sc.simulation.plant.clock.seconds(sc.simulation.duration_ticks);
  j["final_error_m"] = {{"mean", mean}, {"p50", pct(0.5)}, {"p99", pct(0.99)}, {"max", sorted.back()}};
  j["vehicles_in_safety"] = safety;
  j["vehicles_non_finite"] = non_finite;
  j["recorded_vehicles"] = spec.record_vehicles;
  std::ofstream(out / "summary.json") << j.dump(2) << '\n';
  std::cout << fmt::format(
      "swarm: {} vehicles, final position error mean {:.3g} m, p99 {:.3g} m, max {:.3g} m; "
      "{} in safety\n",
      rows.size(), mean, pct(0.99), sorted.back(), safety);
}

int run_swarm(const RunOptions& opt, const io::Scenario& sc, const fs::path& out, io::OutputFolder& folder,
              const nlohmann::json& provenance) {
  const io::SwarmSpec spec = swarm_spec(sc, opt.vehicles, opt.threads);
  const int n = spec.layout.vehicles;
  std::vector<std::string> dirs;
  for (int i : spec.record_vehicles) {
    dirs.push_back(dir_of(sim::vehicle_namespace(spec.layout.ns_prefix, i, n)));
    fs::create_directories(out / dirs.back());
    io::write_file_atomically(out / dirs.back() / "scenario.yaml",
                              io::effective_scenario_text(opt.scenario, opt.controller));
  }
  if (opt.transport == "dds") {
    // The plant process records; the controller process answers.
    const std::string self = self_executable();
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
    if (opt.pin) pin_apart(plant_args, controller_args);
    install_stop_handlers();
    if (const int rc = run_plant_and_controller(plant_args, controller_args); rc != 0) return rc;
  } else {
    sim::Swarm swarm(sc.simulation, sc.vehicle, io::initial_state(sc), sc.controller, sc.schedule, spec.layout);
    std::vector<bool> recorded(static_cast<std::size_t>(n), false);
    std::vector<std::unique_ptr<io::TrajectoryWriter>> writers(static_cast<std::size_t>(n));
    for (std::size_t j = 0; j < dirs.size(); ++j) {
      const auto i = static_cast<std::size_t>(spec.record_vehicles[j]);
      recorded[i] = true;
      writers[i] = std::make_unique<io::TrajectoryWriter>((out / dirs[j] / "trajectory.csv").string());
    }
    const auto start = std::chrono::steady_clock::now();
    swarm.run(spec.threads, kSwarmBlockTicks, recorded, [&](int i, const sim::TickRecord& r) {
      writers[static_cast<std::size_t>(i)]->write(r.t_s, r.state, r.latched_command,
                                                  io::ControlColumns::from(r.status));
    });
    const double wall_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    for (auto& w : writers) {
      if (w) w->close();
    }
    std::vector<SwarmFinal> rows(static_cast<std::size_t>(n));
    std::vector<std::string> namespaces(static_cast<std::size_t>(n));
    for (int i = 0; i < n; ++i) {
      const sim::Simulation& v = swarm.vehicle(i);
      auto& r = rows[static_cast<std::size_t>(i)];
      r.p_W = v.plant().state().p_W;
      r.p_des_W = v.controller().reference().p_W;
      r.safety = v.controller().last_output().safety;
      r.rejected = v.plant().stats().commands_rejected;
      namespaces[static_cast<std::size_t>(i)] = swarm.vehicle_ns(i);
    }
    const double sim_s = sc.simulation.plant.clock.seconds(sc.simulation.duration_ticks);
    write_swarm_summary(out, sc, spec, namespaces, rows,
                        {{"transport", "inproc"},
                         {"threads", spec.threads},
                         {"block_ticks", kSwarmBlockTicks},
                         {"wall_s", wall_s},
                         {"real_time_factor", sim_s / wall_s}});
    std::cout << fmt::format("swarm: {:g} s simulated in {:.3f} s ({:.1f}x real time, {} threads)\n", sim_s, wall_s,
                             sim_s / wall_s, spec.threads);
  }
  const io::Judge judge = io::parse_judge(opt.judge).value_or(io::Judge::kSpec);  // --judge checked its value
  const nlohmann::json recorded = judge_recorded(out, sc, spec.record_vehicles, dirs, judge, provenance);
  // A recorded vehicle's "passed" is null under --judge none: no verdict, nothing fails.
  const bool pass = std::all_of(recorded.begin(), recorded.end(), [](const nlohmann::json& e) {
    return e["passed"].is_null() || e["passed"].get<bool>();
  });
  {  // summary.json (written by whichever process ran the swarm) gains the recorded vehicles' verdicts
    nlohmann::json summary;
    std::ifstream(out / "summary.json") >> summary;
    summary["recorded"] = recorded;
    summary["provenance"] = provenance;
    std::ofstream f(out / "summary.json");
    f << summary.dump(2) << '\n';
    if (!f) throw std::runtime_error("cannot write " + (out / "summary.json").string());
  }
  std::cout << "wrote " << (out / "summary.json").string() << ", vehicles.csv"
            << (dirs.empty() ? "" : fmt::format(", {} recorded vehicle(s)", dirs.size())) << '\n';
  if (opt.plots) {
    for (const std::string& d : dirs) {
      if (!make_plots((out / d).string(), folder)) return exit_code::kOutput;
    }
  }
  return pass ? 0 : 1;
}

}  // namespace quadcosim::app
