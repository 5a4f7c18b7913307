// `quadcosim margins [SCENARIO] [--out DIR] [--json] [--no-plots]`: gain, phase and delay margins of
// every loop of the scenario's controller, linearised about level hover, sampled at the controller's
// rate with the scenario's command delay and sensor latencies (analysis/hover_loops.hpp,
// docs/margins.md).
#include <fmt/format.h>
#include <CLI/CLI.hpp>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <nlohmann/json.hpp>
#include <numbers>
#include <optional>

#include "analysis/hover_loops.hpp"
#include "analysis/margins.hpp"
#include "app/commands.hpp"
#include "app/exit_codes.hpp"
#include "controllers/registry.hpp"
#include "io/output_folder.hpp"
#include "io/scenario.hpp"
#include "sim/topics.hpp"

namespace quadcosim::app {

namespace {

constexpr double kDeg = 180.0 / std::numbers::pi;
using analysis::MarginStatus;

struct Setup {
  std::string source;  ///< the scenario path, or "defaults"
  model::VehicleParams plant;
  control::ControllerConfig controller;
  analysis::LoopTiming timing;
  std::vector<std::string> notes;  ///< what the linearisation leaves out, said once each
};

int delay_of(const sim::FaultConfig& f, const std::string& topic) {
  const auto it = f.topics.find(topic);
  return it == f.topics.end() ? 0 : static_cast<int>(it->second.delay_ticks);
}

// The scenario's controller after its schedule, its plant and its timing. Throws io::ConfigError
// (bad file) or std::invalid_argument (a refused scheduled change).
Setup setup_from(const std::string& path) {
  Setup s;
  if (path.empty()) {
    s.source = "defaults (the paper's vehicle and controller, plant 100 Hz, controller 50 Hz)";
    s.controller = controllers::make_config("paper", s.plant);
    return s;
  }
  const io::Scenario sc = io::load_scenario(path);
  s.source = path;
  s.plant = sc.vehicle;
  s.controller = sc.controller;
  if (!controllers::paper_controller(s.controller)) {
    throw std::invalid_argument(
        fmt::format("{}: margins analyses the paper controller's loops; this scenario flies controller type '{}'", path,
                    s.controller.type()));
  }
  bool later_design_change = false;
  std::vector<sim::ScheduledParameter> schedule = sc.schedule;
  std::stable_sort(schedule.begin(), schedule.end(), [](const auto& a, const auto& b) { return a.tick < b.tick; });
  for (const sim::ScheduledParameter& p : schedule) {
    if (std::string why = control::set_parameter(s.controller, p.name, p.value); !why.empty())
      throw std::invalid_argument(fmt::format("{}: schedule: {}", path, why));
    const control::ParameterSpec* spec = control::find_parameter(s.controller, p.name);
    if (p.tick > 0 && spec != nullptr && (spec->affects_design || p.name == "mode")) later_design_change = true;
  }
  if (later_design_change)
    s.notes.push_back(
        "the schedule changes gains or mode after t = 0: these are the margins of the configuration "
        "after its last change");

  const sim::SimulationConfig& sim = sc.simulation;
  const sim::Topics topics = sim::Topics::for_namespace(sim.ns);
  s.timing.tick_s = sim.plant.clock.period_s();
  s.timing.controller_divider = sim.controller_divider;
  s.timing.command_delay_ticks = sim.plant.command_delay_ticks + delay_of(sim.faults, topics.motor_commands);
  s.timing.imu_latency_ticks = sim.plant.realism.imu.timing.latency_ticks + delay_of(sim.faults, topics.imu);
  s.timing.pose_latency_ticks = sim.plant.realism.pose.timing.latency_ticks + delay_of(sim.faults, topics.pose);
  s.timing.velocity_latency_ticks =
      sim.plant.realism.velocity.timing.latency_ticks + delay_of(sim.faults, topics.velocity);

  const sim::RealismConfig& r = sim.plant.realism;
  const bool noise = r.imu.gyro_noise_density > 0 || r.imu.accel_noise_density > 0 || r.imu.orientation_sigma_rad > 0 ||
                     r.imu.gyro_bias_random_walk > 0 || r.imu.gyro_bias_initial > 0 || r.pose.position_sigma_m > 0 ||
                     r.pose.orientation_sigma_rad > 0 || r.velocity.linear_sigma_m_s > 0 ||
                     r.velocity.angular_sigma_rad_s > 0;
  if (noise) s.notes.push_back("sensor noise and bias are not part of the linear loops");
  if (r.wind.active()) s.notes.push_back("wind is not part of the linearisation (still air)");
  if (!r.faults.empty()) s.notes.push_back("rotor faults are not part of the linearisation (all rotors nominal)");
  for (const auto& [topic, f] : sim.faults.topics) {
    if (f.drop_probability > 0.0) {
      s.notes.push_back("message drops are not part of the linear loops (" + topic + ")");
    }
  }
  if (s.plant.aero.quadratic_drag_N_s2_m2.squaredNorm() > 0.0)
    s.notes.push_back("quadratic drag vanishes at hover in still air");
  if (s.plant.aero.ground_effect_rotor_radius_m > 0.0)
    s.notes.push_back("ground effect is not part of the linearisation (out of ground effect)");
  if (s.plant.motor.model == model::MotorModel::kFirstOrder && s.plant.motor.tau_up_s != s.plant.motor.tau_down_s)
    s.notes.push_back(fmt::format("motor lag linearised with the larger time constant, {:g} s",
                                  std::max(s.plant.motor.tau_up_s, s.plant.motor.tau_down_s)));
  const double worst_age_s = s.timing.tick_s * std::max({s.timing.imu_latency_ticks, s.timing.pose_latency_ticks,
                                                         s.timing.velocity_latency_ticks});
  if (worst_age_s > s.controller.node.stale_limit_s)
    s.notes.push_back(
        fmt::format("sensor latency {:g} s exceeds stale_limit {:g} s: the controller would command "
                    "its safety mode, which these loops do not model",
                    worst_age_s, s.controller.node.stale_limit_s));
  return s;
}

nlohmann::json margin_json(const analysis::Margin& m, const char* unit, double scale) {
  nlohmann::json j;
  j["status"] = to_string(m.status);
  if (m.status == MarginStatus::kFinite) {
    j[unit] = m.value * scale;
    j["frequency_rad_s"] = m.frequency_rad_s;
  } else {
    j[unit] = nullptr;
    j["frequency_rad_s"] = nullptr;
  }
  return j;
}

std::string cell(const analysis::Margin& m, double scale, const char* infinite, int precision = 2) {
  switch (m.status) {
    case MarginStatus::kFinite: return fmt::format("{:.{}f}", m.value * scale, precision);
    case MarginStatus::kInfinite: return infinite;
    case MarginStatus::kUndefined: return "undefined";
  }
  return "undefined";
}

std::string freq_cell(const analysis::Margin& m) {
  return m.status == MarginStatus::kFinite ? fmt::format("{:.3g}", m.frequency_rad_s) : "-";
}

analysis::Margin gain_db(analysis::Margin m) {
  if (m.status == MarginStatus::kFinite) m.value = 20.0 * std::log10(m.value);
  return m;
}

bool write_file(const std::filesystem::path& p, const std::string& text) {
  std::ofstream f(p);
  f << text;
  f.close();
  if (!f) {
    std::cerr << "error: cannot write " << p.string() << '\n';
    return false;
  }
  return true;
}

}  // namespace

CLI::App* add_margins_subcommand(CLI::App& app, MarginsOptions& o) {
  auto* cmd =
      app.add_subcommand("margins", "gain, phase and delay margins of each control loop about hover (docs/margins.md)");
  cmd->add_option("scenario", o.scenario, "scenario YAML (default: the paper's vehicle and controller)")
      ->check(CLI::ExistingFile);
  cmd->add_option("--out", o.out_dir,
                  "write margins.json, frequency_response.csv and Bode/Nyquist PNGs here: a new or empty folder");
  cmd->add_flag("--force", o.force,
                "--out holds a previous command's outputs or other files: remove exactly the outputs its manifest "
                "lists first (files quadcosim did not write are kept)");
  cmd->add_flag("--json", o.json, "print the margins as one JSON object instead of the table");
  cmd->add_flag("!--no-plots", o.plots, "with --out: skip the PNGs");
  return cmd;
}

int margins_command(const MarginsOptions& o) {
  if (!o.plots && o.out_dir.empty()) {
    std::cerr << "error: --no-plots needs --out (plots are only written into an output directory)\n";
    return exit_code::kBadInput;
  }
  if (o.force && o.out_dir.empty()) {
    std::cerr << "error: --force needs --out (it concerns the output folder)\n";
    return exit_code::kBadInput;
  }
  // A bad file (io::ConfigError), a failed LQR design (control::CareError) or a vehicle that cannot
  // hover: bad input (run_guarded).
  Setup s;
  std::vector<analysis::HoverLoop> loops;
  try {
    s = setup_from(o.scenario);
    s.notes.push_back(
        "the loops are linearised: the rotor clamp, the tilt limit and the integral bound are not "
        "in them");
    loops = analysis::hover_loops(s.plant, *controllers::paper_controller(s.controller),
                                  s.controller.node.setpoint.mode, s.timing);
  } catch (const std::invalid_argument& e) {
    throw std::invalid_argument(
        fmt::format("{}cannot linearise about hover: {}", o.scenario.empty() ? "" : o.scenario + ": ", e.what()));
  }
  std::optional<io::OutputFolder> folder;
  if (!o.out_dir.empty()) folder.emplace(io::OutputFolder::claim(o.out_dir, "margins", {.force = o.force}, std::cerr));

  const analysis::LoopTiming& t = s.timing;
  const double T = t.tick_s * t.controller_divider;
  std::vector<analysis::LoopMargins> results;
  for (const auto& l : loops) results.push_back(analysis::analyse_margins(l.loop));

  nlohmann::json doc;
  doc["scenario"] = s.source;
  doc["linearised_about"] = "level hover, still air";
  doc["mode"] = control::to_string(s.controller.node.setpoint.mode);
  doc["plant_period_s"] = t.tick_s;
  doc["controller_period_s"] = T;
  doc["command_delay_ticks"] = t.command_delay_ticks;
  doc["latency_ticks"] = {
      {"imu", t.imu_latency_ticks}, {"pose", t.pose_latency_ticks}, {"velocity", t.velocity_latency_ticks}};
  doc["notes"] = s.notes;
  doc["loops"] = nlohmann::json::array();
  bool all_stable = true;
  for (std::size_t i = 0; i < loops.size(); ++i) {
    const analysis::LoopMargins& m = results[i];
    all_stable = all_stable && m.closed_loop_stable;
    nlohmann::json j;
    j["name"] = loops[i].name;
    j["broken_at"] = loops[i].broken_at;
    j["closed_loop_stable"] = m.closed_loop_stable;
    j["open_loop_unstable_poles"] = m.open_loop_unstable_poles;
    j["open_loop_marginal_poles"] = m.open_loop_marginal_poles;
    nlohmann::json gm = margin_json(m.gain_margin, "factor", 1.0);
    gm["db"] = m.gain_margin.status == MarginStatus::kFinite ? nlohmann::json(20 * std::log10(m.gain_margin.value))
                                                             : nlohmann::json(nullptr);
    j["gain_margin"] = gm;
    nlohmann::json gr = margin_json(m.gain_reduction_margin, "factor", 1.0);
    gr["db"] = m.gain_reduction_margin.status == MarginStatus::kFinite
                   ? nlohmann::json(20 * std::log10(m.gain_reduction_margin.value))
                   : nlohmann::json(nullptr);
    j["gain_reduction_margin"] = gr;
    j["phase_margin"] = margin_json(m.phase_margin, "deg", kDeg);
    nlohmann::json dm = margin_json(m.delay_margin, "s", 1.0);
    dm["samples"] = m.delay_margin.status == MarginStatus::kFinite ? nlohmann::json(m.delay_margin.value / T)
                                                                   : nlohmann::json(nullptr);
    j["delay_margin"] = dm;
    j["gain_crossovers_rad_s"] = m.gain_crossovers_rad_s;
    j["phase_crossovers_rad_s"] = m.phase_crossovers_rad_s;
    nlohmann::json ranges = nlohmann::json::array();
    for (const auto& [lo, hi] : m.stable_gain_ranges)
      ranges.push_back({lo, std::isinf(hi) ? nlohmann::json(nullptr) : nlohmann::json(hi)});
    j["stable_gain_ranges"] = ranges;
    // Poles at z = 0 are the delay lines' and the hold's: listed in z, left out in s.
    nlohmann::json pz = nlohmann::json::array(), ps = nlohmann::json::array();
    for (Eigen::Index k = 0; k < m.closed_loop_poles.size(); ++k) {
      const std::complex<double> z = m.closed_loop_poles(k);
      pz.push_back({z.real(), z.imag()});
      if (std::abs(z) > 1e-9) {
        const std::complex<double> sp = std::log(z) / T;
        ps.push_back({sp.real(), sp.imag()});
      }
    }
    j["closed_loop_poles_z"] = pz;
    j["closed_loop_poles_s"] = ps;
    doc["loops"].push_back(j);
  }

  std::string table;
  table += fmt::format("margins of {}\n", s.source);
  table += fmt::format(
      "linearised about level hover ({} mode); controller {:g} Hz (T = {:g} s, zero-order hold), "
      "plant {:g} Hz; command delay {} ticks; sensor latency imu {}, pose {}, velocity {} ticks\n",
      control::to_string(s.controller.node.setpoint.mode), 1.0 / T, T, 1.0 / t.tick_s, t.command_delay_ticks,
      t.imu_latency_ticks, t.pose_latency_ticks, t.velocity_latency_ticks);
  table += fmt::format("{:<11} {:<30} {:>8} {:>9} {:>9} {:>8} {:>9} {:>8} {:>9} {}\n", "loop", "broken at", "GM [dB]",
                       "w_pc", "GMlo[dB]", "PM [deg]", "w_gc", "DM [s]", "DM [smp]", "closed loop");
  for (std::size_t i = 0; i < loops.size(); ++i) {
    const analysis::LoopMargins& m = results[i];
    std::string status = m.closed_loop_stable ? "stable" : "UNSTABLE: margins undefined";
    if (m.open_loop_unstable_poles > 0)
      status += fmt::format(" (open loop unstable: {} pole{})", m.open_loop_unstable_poles,
                            m.open_loop_unstable_poles == 1 ? "" : "s");
    analysis::Margin dms = m.delay_margin;
    if (dms.status == MarginStatus::kFinite) dms.value /= T;
    table +=
        fmt::format("{:<11} {:<30} {:>8} {:>9} {:>9} {:>8} {:>9} {:>8} {:>9} {}\n", loops[i].name, loops[i].broken_at,
                    cell(gain_db(m.gain_margin), 1.0, "inf"), freq_cell(m.gain_margin),
                    cell(gain_db(m.gain_reduction_margin), 1.0, "-inf"), cell(m.phase_margin, kDeg, "inf", 1),
                    freq_cell(m.phase_margin), cell(m.delay_margin, 1.0, "inf", 3), cell(dms, 1.0, "inf", 1), status);
  }
  table += "w_pc, w_gc [rad/s]: phase and gain crossover; GMlo: gain reduction margin (-inf: the gain may drop to 0)\n";
  for (const std::string& n : s.notes) table += "note: " + n + '\n';

  if (o.json)
    std::cout << doc.dump(2) << '\n';
  else
    std::cout << table;

  if (folder) {
    const std::filesystem::path out(o.out_dir);
    std::string csv = "loop,omega_rad_s,re,im,magnitude_db,phase_deg\n";
    analysis::MarginOptions grid;
    grid.points = 1500;
    for (const auto& l : loops) {
      for (const analysis::FrequencyPoint& p : analysis::frequency_response(l.loop, grid)) {
        if (!std::isfinite(p.L.real()) || !std::isfinite(p.L.imag())) continue;
        csv += fmt::format("{},{:.9g},{:.9g},{:.9g},{:.9g},{:.9g}\n", l.name, p.omega_rad_s, p.L.real(), p.L.imag(),
                           p.magnitude_db, p.phase_deg);
      }
    }
    if (!write_file(out / "margins.json", doc.dump(2) + "\n") || !write_file(out / "margins.txt", table) ||
        !write_file(out / "frequency_response.csv", csv))
      return exit_code::kOutput;
    if (o.plots && !run_tool("plot_margins.py", {o.out_dir})) return exit_code::kOutput;
    folder->record("outputs");
  }
  return all_stable ? exit_code::kOk : exit_code::kFailed;
}

}  // namespace quadcosim::app
