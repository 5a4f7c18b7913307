// `quadcosim sweep SCENARIO --runs N --seed S --vary mass=10% ... --out DIR`: Monte Carlo over
// model uncertainty and the scenario's noise. Run i gets its own seed (stream_seed(S, "sweep",
// "run/<i>")); from it each varied vehicle parameter draws its factor from its own stream, uniform in
// [1 - P, 1 + P], and the scenario's noise and gusts are seeded with it. The plant flies the perturbed
// vehicle; the controller keeps the nominal one (it was designed for it). Runs are in-process
// simulations on a pool of --jobs threads; results are kept by run index, so summary.json is the same
// bytes whatever the scheduling.
#include <fmt/format.h>

#include <CLI/CLI.hpp>
#include <algorithm>
#include <atomic>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <map>
#include <nlohmann/json.hpp>
#include <optional>
#include <set>
#include <thread>

#include "app/commands.hpp"
#include "control/care.hpp"
#include "io/scenario.hpp"
#include "io/step_report.hpp"
#include "io/trajectory_csv.hpp"
#include "model/attitude.hpp"
#include "model/random.hpp"
#include "sim/simulation.hpp"

namespace quadcosim::app {

namespace fs = std::filesystem;

namespace {

// A vehicle field that --vary may scale: its name (the stream it draws from) and where it lives.
struct Field {
  const char* name;
  double* (*get)(model::VehicleParams&);
};

#define QUADCOSIM_FIELD(NAME, EXPR) \
  Field { NAME, [](model::VehicleParams& v) -> double* { return &(EXPR); } }

const std::vector<Field>& all_fields() {
  static const std::vector<Field> fields = {
      QUADCOSIM_FIELD("mass_kg", v.mass_kg),
      QUADCOSIM_FIELD("gravity_m_s2", v.gravity_m_s2),
      QUADCOSIM_FIELD("Ixx_kg_m2", v.Ixx_kg_m2),
      QUADCOSIM_FIELD("Iyy_kg_m2", v.Iyy_kg_m2),
      QUADCOSIM_FIELD("Izz_kg_m2", v.Izz_kg_m2),
      QUADCOSIM_FIELD("arm_length_m", v.arm_length_m),
      QUADCOSIM_FIELD("kt_N_per_rad2_s2", v.kt_N_per_rad2_s2),
      QUADCOSIM_FIELD("km_Nm_per_rad2_s2", v.km_Nm_per_rad2_s2),
      QUADCOSIM_FIELD("motor.tau_up_s", v.motor.tau_up_s),
      QUADCOSIM_FIELD("motor.tau_down_s", v.motor.tau_down_s),
      QUADCOSIM_FIELD("motor.omega_max_rad_s", v.motor.omega_max_rad_s),
      QUADCOSIM_FIELD("aero.linear_drag_N_s_m.x", v.aero.linear_drag_N_s_m.x()),
      QUADCOSIM_FIELD("aero.linear_drag_N_s_m.y", v.aero.linear_drag_N_s_m.y()),
      QUADCOSIM_FIELD("aero.linear_drag_N_s_m.z", v.aero.linear_drag_N_s_m.z()),
      QUADCOSIM_FIELD("aero.quadratic_drag_N_s2_m2.x", v.aero.quadratic_drag_N_s2_m2.x()),
      QUADCOSIM_FIELD("aero.quadratic_drag_N_s2_m2.y", v.aero.quadratic_drag_N_s2_m2.y()),
      QUADCOSIM_FIELD("aero.quadratic_drag_N_s2_m2.z", v.aero.quadratic_drag_N_s2_m2.z()),
      QUADCOSIM_FIELD("aero.rotor_drag_N_s_m_per_rad_s", v.aero.rotor_drag_N_s_m_per_rad_s),
      QUADCOSIM_FIELD("aero.ground_effect_rotor_radius_m", v.aero.ground_effect_rotor_radius_m),
  };
  return fields;
}
#undef QUADCOSIM_FIELD

// Short names users type, each standing for one or more fields (each field draws independently).
const std::map<std::string, std::vector<std::string>>& aliases() {
  static const std::map<std::string, std::vector<std::string>> a = {
      {"mass", {"mass_kg"}},
      {"gravity", {"gravity_m_s2"}},
      {"inertia", {"Ixx_kg_m2", "Iyy_kg_m2", "Izz_kg_m2"}},
      {"Ixx", {"Ixx_kg_m2"}},
      {"Iyy", {"Iyy_kg_m2"}},
      {"Izz", {"Izz_kg_m2"}},
      {"arm", {"arm_length_m"}},
      {"kt", {"kt_N_per_rad2_s2"}},
      {"km", {"km_Nm_per_rad2_s2"}},
      {"motor_tau", {"motor.tau_up_s", "motor.tau_down_s"}},
      {"omega_max", {"motor.omega_max_rad_s"}},
      {"linear_drag", {"aero.linear_drag_N_s_m.x", "aero.linear_drag_N_s_m.y", "aero.linear_drag_N_s_m.z"}},
      {"quadratic_drag",
       {"aero.quadratic_drag_N_s2_m2.x", "aero.quadratic_drag_N_s2_m2.y", "aero.quadratic_drag_N_s2_m2.z"}},
      {"rotor_drag", {"aero.rotor_drag_N_s_m_per_rad_s"}},
      {"ground_effect_radius", {"aero.ground_effect_rotor_radius_m"}},
  };
  return a;
}

struct Vary {
  std::string key;     ///< as typed
  double fraction;     ///< P / 100
  std::vector<const Field*> fields;
};

std::string known_keys() {
  std::string s;
  for (const auto& [k, _] : aliases()) s += (s.empty() ? "" : ", ") + k;
  s += " or a field name such as mass_kg, motor.tau_up_s, aero.linear_drag_N_s_m.x";
  return s;
}

// "mass=10%" -> Vary; throws std::invalid_argument naming the spec.
Vary parse_vary(const std::string& spec) {
  const auto eq = spec.find('=');
  if (eq == std::string::npos || spec.back() != '%') {
    throw std::invalid_argument("--vary " + spec + ": expected KEY=P% (e.g. mass=10%)");
  }
  Vary v;
  v.key = spec.substr(0, eq);
  const std::string number = spec.substr(eq + 1, spec.size() - eq - 2);
  char* end = nullptr;
  const double p = std::strtod(number.c_str(), &end);
  if (number.empty() || end != number.c_str() + number.size() || !std::isfinite(p) || p < 0.0 || p >= 100.0) {
    throw std::invalid_argument("--vary " + spec + ": got '" + number + "%', expected a percentage in [0, 100)");
  }
  v.fraction = p / 100.0;
  std::vector<std::string> names;
  if (auto a = aliases().find(v.key); a != aliases().end()) {
    names = a->second;
  } else {
    names = {v.key};
  }
  for (const auto& n : names) {
    const auto f = std::find_if(all_fields().begin(), all_fields().end(), [&](const Field& x) { return n == x.name; });
    if (f == all_fields().end()) {
      throw std::invalid_argument("--vary " + spec + ": unknown parameter '" + v.key + "' (expected " + known_keys() + ")");
    }
    v.fields.push_back(&*f);
  }
  return v;
}

struct RunResult {
  std::uint64_t seed = 0;
  std::map<std::string, double> factors;   ///< field -> factor applied
  std::vector<io::StepResult> steps;
  std::optional<io::HoldResult> hold;
  bool passed = false;
  std::string error;  ///< non-empty when the run could not be done
};

io::Series simulate(const io::Scenario& sc, const model::VehicleParams& plant_vehicle) {
  sim::Simulation simulation(sc.simulation, plant_vehicle,
                             model::Quadrotor(plant_vehicle)
                                 .initial_state(sc.initial.p_W, sc.initial.yaw_rad, sc.initial.hover),
                             sc.controller, sc.schedule);
  io::Series s;
  const std::size_t n = static_cast<std::size_t>(sc.simulation.duration_ticks + 1);
  s.t_s.reserve(n);
  const char* names[] = {"x", "y", "z", "roll", "pitch", "yaw", "x_des", "y_des", "z_des", "roll_des", "pitch_des", "yaw_des"};
  for (const char* name : names) s.values[name].reserve(n);
  auto& v = s.values;
  simulation.run([&](const sim::TickRecord& r) {
    // The same numbers trajectory.csv holds (TrajectoryWriter, ControlColumns).
    const model::Euler e = model::euler_from_quaternion(r.state.q_WB);
    const io::ControlColumns c = io::ControlColumns::from(r.status);
    s.t_s.push_back(r.t_s);
    v["x"].push_back(r.state.p_W.x());
    v["y"].push_back(r.state.p_W.y());
    v["z"].push_back(r.state.p_W.z());
    v["roll"].push_back(e.roll_rad);
    v["pitch"].push_back(e.pitch_rad);
    v["yaw"].push_back(e.yaw_rad);
    v["x_des"].push_back(c.x_des);
    v["y_des"].push_back(c.y_des);
    v["z_des"].push_back(c.z_des);
    v["roll_des"].push_back(c.roll_des);
    v["pitch_des"].push_back(c.pitch_des);
    v["yaw_des"].push_back(c.yaw_des);
  });
  return s;
}

RunResult one_run(const io::Scenario& nominal, const std::vector<Vary>& vary, std::uint64_t sweep_seed, int index,
                  const fs::path& run_dir) {
  RunResult r;
  r.seed = model::stream_seed(sweep_seed, "sweep", "run/" + std::to_string(index));
  io::Scenario sc = nominal;
  sc.simulation.plant.realism.seed = r.seed;
  model::VehicleParams plant = nominal.vehicle;
  for (const Vary& v : vary) {
    for (const Field* f : v.fields) {
      model::Rng rng(model::stream_seed(r.seed, "vary", f->name));
      const double factor = 1.0 + v.fraction * (2.0 * rng.uniform() - 1.0);
      *f->get(plant) *= factor;
      r.factors[f->name] = factor;
    }
  }
  try {
    if (std::string err = model::validate(plant); !err.empty()) throw std::invalid_argument(err);
    if (std::string err = model::validate_step(plant, sc.simulation.plant.clock.period_s(), sc.simulation.plant.substeps);
        !err.empty()) {
      throw std::invalid_argument(err);
    }
    const io::Series series = simulate(sc, plant);
    r.steps = io::evaluate_steps(sc.steps, series);
    if (sc.hold) r.hold = io::evaluate_hold(*sc.hold, series);
    r.passed = io::all_passed(r.steps) && (!r.hold || r.hold->passed);
    sc.vehicle = plant;  // metrics.json of the run describes what flew
    fs::create_directories(run_dir);
    io::write_metrics_json((run_dir / "metrics.json").string(), sc, r.steps, r.hold);
  } catch (const std::exception& e) {
    r.error = e.what();
    r.passed = false;
  }
  return r;
}

// Percentile by linear interpolation between closest ranks (numpy's default, "linear").
double percentile(const std::vector<double>& sorted, double q) {
  const double pos = q * static_cast<double>(sorted.size() - 1);
  const auto lo = static_cast<std::size_t>(std::floor(pos));
  const std::size_t hi = std::min(lo + 1, sorted.size() - 1);
  return sorted[lo] + (pos - static_cast<double>(lo)) * (sorted[hi] - sorted[lo]);
}

nlohmann::json distribution(std::vector<double> values, int runs) {
  nlohmann::json j;
  j["count"] = values.size();
  j["missing"] = runs - static_cast<int>(values.size());
  if (values.empty()) return j;
  double sum = 0.0;
  for (double v : values) sum += v;
  const double mean = sum / static_cast<double>(values.size());
  double ss = 0.0;
  for (double v : values) ss += (v - mean) * (v - mean);
  std::sort(values.begin(), values.end());
  j["min"] = values.front();
  j["max"] = values.back();
  j["mean"] = mean;
  j["std"] = values.size() > 1 ? std::sqrt(ss / static_cast<double>(values.size() - 1)) : 0.0;
  for (const auto& [name, q] : std::vector<std::pair<const char*, double>>{
           {"p5", 0.05}, {"p25", 0.25}, {"p50", 0.5}, {"p75", 0.75}, {"p95", 0.95}}) {
    j[name] = percentile(values, q);
  }
  return j;
}

// Figure name in summary.json: "<channel>.<figure>" for steps ("roll.overshoot_pct"; a second step
// of the same channel gets "roll#2.overshoot_pct"), "hold.<figure>" for the hold.
std::vector<std::pair<std::string, std::optional<double>>> figures_of(const RunResult& r,
                                                                        const io::Scenario& sc) {
  std::vector<std::pair<std::string, std::optional<double>>> out;
  std::map<std::string, int> seen;
  for (std::size_t i = 0; i < sc.steps.size(); ++i) {
    const std::string& ch = sc.steps[i].channel;
    const int n = ++seen[ch];
    const std::string prefix = n == 1 ? ch : fmt::format("{}#{}", ch, n);
    for (const auto& name : analysis::figure_names()) {
      out.emplace_back(prefix + "." + name,
                       i < r.steps.size() ? analysis::figure(r.steps[i].figures, name) : std::nullopt);
    }
  }
  if (sc.hold) {
    for (const auto& name : io::hold_figure_names()) {
      std::optional<double> v;
      if (r.hold) {
        if (auto it = r.hold->figures.find(name); it != r.hold->figures.end()) v = it->second;
      }
      out.emplace_back("hold." + name, v);
    }
  }
  return out;
}

}  // namespace

CLI::App* add_sweep_subcommand(CLI::App& app, SweepOptions& o) {
  auto* c = app.add_subcommand("sweep", "Monte Carlo: N runs with perturbed vehicle parameters and seeded noise");
  c->add_option("scenario", o.scenario, "scenario YAML file")->required()->check(CLI::ExistingFile);
  c->add_option("--runs", o.runs, "number of runs")->check(CLI::Range(1, 1000000));
  c->add_option("--seed", o.seed, "sweep seed (run i's seed derives from it)");
  c->add_option("--vary", o.vary, "KEY=P%: scale a vehicle parameter by a factor uniform in [1-P, 1+P] per run (repeatable)");
  c->add_option("--out", o.out_dir, "output directory (created)")->required();
  c->add_option("--jobs", o.jobs, "parallel runs (threads)")->check(CLI::Range(1, 64));
  c->add_option("--min-pass-rate", o.min_pass_rate, "exit 1 when fewer runs than this fraction pass")
      ->check(CLI::Range(0.0, 1.0));
  c->add_flag("!--no-plots", o.plots, "skip the histograms and box plots");
  return c;
}

int sweep_command(const SweepOptions& o) {
  io::Scenario sc;
  std::vector<Vary> vary;
  try {
    sc = io::load_scenario(o.scenario);
    std::set<std::string> used;
    for (const auto& spec : o.vary) {
      vary.push_back(parse_vary(spec));
      for (const Field* f : vary.back().fields) {
        if (!used.insert(f->name).second) {
          throw std::invalid_argument("--vary " + spec + ": " + f->name + " is already varied by an earlier --vary");
        }
      }
    }
  } catch (const io::ConfigError& e) {
    std::cerr << "error: " << e.what() << '\n';
    return 2;
  } catch (const std::invalid_argument& e) {
    std::cerr << "error: " << e.what() << '\n';
    return 2;
  }
  if (sc.steps.empty() && !sc.hold) {
    std::cerr << "error: " << o.scenario << ": analysis: the scenario has no steps and no hold criterion; "
              << "a sweep needs something to judge\n";
    return 2;
  }
  const fs::path out(o.out_dir);
  std::error_code ec;
  fs::create_directories(out / "runs", ec);
  if (ec) {
    std::cerr << "error: cannot create output directory " << o.out_dir << ": " << ec.message() << '\n';
    return 3;
  }

  std::vector<RunResult> results(static_cast<std::size_t>(o.runs));
  std::atomic<int> next{0};
  auto worker = [&] {
    for (int i; (i = next.fetch_add(1)) < o.runs;) {
      results[static_cast<std::size_t>(i)] = one_run(sc, vary, o.seed, i, out / "runs" / fmt::format("{:04d}", i));
    }
  };
  std::vector<std::thread> pool;
  for (int t = 0; t < std::min(o.jobs, o.runs); ++t) pool.emplace_back(worker);
  for (auto& t : pool) t.join();

  for (std::size_t i = 0; i < results.size(); ++i) {
    if (!results[i].error.empty()) {
      std::cerr << fmt::format("sweep: run {} (seed {}) failed: {}\n", i, results[i].seed, results[i].error);
    }
  }

  nlohmann::json j;
  j["scenario"] = sc.name;
  j["scenario_file"] = o.scenario;
  j["seed"] = o.seed;
  j["runs"] = o.runs;
  const int passed = static_cast<int>(std::count_if(results.begin(), results.end(), [](const auto& r) { return r.passed; }));
  j["passed"] = passed;
  j["pass_rate"] = static_cast<double>(passed) / o.runs;
  j["distribution"] = "uniform";
  j["vary"] = nlohmann::json::array();
  for (const Vary& v : vary) {
    nlohmann::json fields = nlohmann::json::array();
    for (const Field* f : v.fields) fields.push_back(f->name);
    j["vary"].push_back({{"key", v.key}, {"percent", v.fraction * 100.0}, {"fields", fields}});
  }
  std::map<std::string, std::vector<double>> values;
  std::vector<std::string> order;
  j["per_run"] = nlohmann::json::array();
  for (std::size_t i = 0; i < results.size(); ++i) {
    const RunResult& r = results[i];
    nlohmann::json run = {{"index", i}, {"seed", r.seed}, {"passed", r.passed}};
    run["factors"] = r.factors;
    nlohmann::json figs = nlohmann::json::object();
    for (const auto& [name, v] : figures_of(r, sc)) {
      if (!values.count(name)) order.push_back(name);
      auto& list = values[name];
      if (v && r.error.empty()) list.push_back(*v);
      figs[name] = v && r.error.empty() ? nlohmann::json(*v) : nlohmann::json();
    }
    run["figures"] = figs;
    if (!r.error.empty()) run["error"] = r.error;
    j["per_run"].push_back(run);
  }
  nlohmann::json dist = nlohmann::json::object();
  for (const auto& name : order) dist[name] = distribution(values[name], o.runs);
  j["figures"] = dist;
  {
    std::ofstream f(out / "summary.json");
    f << j.dump(2) << '\n';
    if (!f) {
      std::cerr << "error: " << (out / "summary.json").string() << ": write failed\n";
      return 3;
    }
  }
  std::cout << fmt::format("sweep {}: {} of {} runs passed ({:.1f} %), seed {}\n", sc.name, passed, o.runs,
                           100.0 * passed / o.runs, o.seed);
  for (const auto& name : order) {
    const auto& d = dist[name];
    if (d["count"].get<int>() == 0) continue;
    std::cout << fmt::format("  {:<36} mean {:>10.4g}  std {:>10.4g}  min {:>10.4g}  p50 {:>10.4g}  p95 {:>10.4g}  max {:>10.4g}\n",
                             name, d["mean"].get<double>(), d["std"].get<double>(), d["min"].get<double>(),
                             d["p50"].get<double>(), d["p95"].get<double>(), d["max"].get<double>());
  }
  std::cout << "wrote " << (out / "summary.json").string() << " and runs/NNNN/metrics.json\n";
  if (o.plots && !run_tool("plot_sweep.py", {o.out_dir})) return 3;
  return static_cast<double>(passed) >= o.min_pass_rate * o.runs ? 0 : 1;
}

}  // namespace quadcosim::app
