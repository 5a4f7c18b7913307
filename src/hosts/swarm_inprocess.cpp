#include "hosts/swarm_inprocess.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <fstream>
#include <memory>

#include "analysis/percentile.hpp"
#include "hosts/recording.hpp"
#include "io/output_folder.hpp"
#include "io/provenance.hpp"
#include "sim/swarm.hpp"

namespace quadcosim::hosts {

namespace fs = std::filesystem;

io::SwarmSpec swarm_spec(const io::Scenario& sc, int vehicles, int threads) {
  io::SwarmSpec spec = sc.swarm.value_or(io::SwarmSpec{});
  if (vehicles > 0) spec.layout.vehicles = vehicles;
  if (threads > 0) spec.threads = threads;
  std::erase_if(spec.record_vehicles, [&](int i) { return i >= spec.layout.vehicles; });
  return spec;
}

std::vector<std::string> make_recorded_dirs(const fs::path& out, const io::SwarmSpec& spec,
                                            const std::string& scenario_yaml) {
  std::vector<std::string> dirs;
  for (int i : spec.record_vehicles) {
    // "/uav0003" -> "uav0003"
    dirs.push_back(sim::vehicle_namespace(spec.layout.ns_prefix, i, spec.layout.vehicles).substr(1));
    fs::create_directories(out / dirs.back());
    io::write_file_atomically(out / dirs.back() / "scenario.yaml", scenario_yaml);
  }
  return dirs;
}

void write_swarm_summary(const fs::path& out, const io::Scenario& sc, const io::SwarmSpec& spec,
                         const std::vector<std::string>& namespaces, const std::vector<SwarmFinal>& rows,
                         const nlohmann::json& run_figures, std::ostream& info) {
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
  info << fmt::format(
      "swarm: {} vehicles, final position error mean {:.3g} m, p99 {:.3g} m, max {:.3g} m; "
      "{} in safety\n",
      rows.size(), mean, pct(0.99), sorted.back(), safety);
}

bool fly_swarm_inprocess(const io::Scenario& sc, const io::SwarmSpec& spec, const fs::path& out, std::ostream& info,
                         const std::function<bool(double t_s)>& on_block) {
  const int n = spec.layout.vehicles;
  sim::Swarm swarm(sc.simulation, sc.vehicle, io::initial_state(sc), sc.controller, sc.schedule, spec.layout);
  std::vector<bool> recorded(static_cast<std::size_t>(n), false);
  std::vector<io::Recording> recordings(static_cast<std::size_t>(n));
  for (int i : spec.record_vehicles) {
    const std::string dir = sim::vehicle_namespace(spec.layout.ns_prefix, i, n).substr(1);
    recorded[static_cast<std::size_t>(i)] = true;
    RecordingOptions ro;
    ro.csv = (out / dir / "trajectory.csv").string();
    recordings[static_cast<std::size_t>(i)] = make_recording(ro, nullptr);
  }
  const auto record = [&](int i, const sim::TickRecord& r) {  // a swarm's rows show no watchdog
    recordings[static_cast<std::size_t>(i)].tick(
        {r.tick, r.t_s, sc.simulation.plant.clock.ns(r.tick), r.state, r.latched_command, &r.status, false});
  };
  const auto start = std::chrono::steady_clock::now();
  const bool completed = swarm.run(spec.threads, kSwarmBlockTicks, recorded, record,
                                   on_block ? sim::Swarm::StopCheck([&](sim::Tick last) {
                                     return on_block(sc.simulation.plant.clock.seconds(last));
                                   })
                                            : sim::Swarm::StopCheck());
  const double wall_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  for (auto& r : recordings) r.finish(completed);
  if (!completed) return false;
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
                       {"real_time_factor", sim_s / wall_s}},
                      info);
  info << fmt::format("swarm: {:g} s simulated in {:.3f} s ({:.1f}x real time, {} threads)\n", sim_s, wall_s,
                      sim_s / wall_s, spec.threads);
  return true;
}

SwarmJudgement judge_swarm(const io::Scenario& sc, const io::SwarmSpec& spec, const fs::path& out, io::Judge judge,
                           const nlohmann::json& provenance) {
  SwarmJudgement verdict;
  for (int vehicle : spec.record_vehicles) {
    const std::string dir = sim::vehicle_namespace(spec.layout.ns_prefix, vehicle, spec.layout.vehicles).substr(1);
    const fs::path folder = out / dir;
    const io::Series series = io::read_series((folder / "trajectory.csv").string());
    const auto results = io::evaluate_steps(sc.steps, series, judge);
    const auto saturation = io::evaluate_saturation(sc, series, judge);
    const nlohmann::json metrics = io::metrics_json(sc, results, {}, saturation, {}, judge);
    io::write_metrics_with_provenance(folder / "metrics.json", metrics, provenance);
    io::write_file_atomically(folder / "metrics.txt", io::format_step_table(sc, results, {}, saturation, {}, judge));
    if (saturation) {
      if (const std::string w = io::saturation_warning(*saturation); !w.empty())
        verdict.warnings.push_back(dir + ": " + w);
    }
    // A recorded vehicle's "passed" is null under --judge none: no verdict, nothing fails.
    nlohmann::json e = {{"vehicle", vehicle}, {"namespace", "/" + dir}, {"passed", metrics.at("passed")}};
    e["saturation"] = metrics.contains("saturation") ? metrics["saturation"]["figures"] : nlohmann::json();
    if (!e["passed"].is_null() && !e["passed"].get<bool>()) verdict.passed = false;
    verdict.recorded.push_back(e);
  }
  // summary.json (written by whichever process ran the swarm) gains the recorded vehicles' verdicts
  nlohmann::json summary;
  std::ifstream(out / "summary.json") >> summary;
  summary["recorded"] = verdict.recorded;
  summary["provenance"] = provenance;
  io::write_file_atomically(out / "summary.json", summary.dump(2) + '\n');
  return verdict;
}

}  // namespace quadcosim::hosts
