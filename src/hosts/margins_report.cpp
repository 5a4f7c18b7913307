// hosts/margins_report.hpp: the analytic and measured margins about hover, as JSON, a table and CSVs.
#include "hosts/margins_report.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <complex>
#include <numbers>
#include <stdexcept>

#include "analysis/margins.hpp"
#include "controllers/paper/paper_controller.hpp"

namespace quadcosim::hosts {

namespace {

constexpr double kDeg = 180.0 / std::numbers::pi;
using analysis::MarginStatus;

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

// The measured margins of every hover loop: the table's rows, the JSON, the response CSV rows.
struct MeasuredReport {
  nlohmann::json doc;
  std::string table;
  std::string csv;  ///< measured_response.csv without its header
  bool all_in_hover = true;
};

nlohmann::json measured_margin_json(const analysis::Margin& m, const char* unit, double scale) {
  nlohmann::json j = margin_json(m, unit, scale);
  if (m.status == MarginStatus::kInfinite) j["status"] = "none_in_band";  // no crossing measured
  return j;
}

// The margins of one loop into `j` (analytic or measured: `to_json` says how one margin reads), with
// the gain margins also in dB and the delay margin also in control periods of `period_s`.
template <class Margins>
void put_margins(nlohmann::json& j, const Margins& m, double period_s,
                 nlohmann::json (*to_json)(const analysis::Margin&, const char*, double)) {
  const auto with_db = [&](const analysis::Margin& g) {
    nlohmann::json x = to_json(g, "factor", 1.0);
    x["db"] = g.status == MarginStatus::kFinite ? nlohmann::json(20 * std::log10(g.value)) : nlohmann::json(nullptr);
    return x;
  };
  j["gain_margin"] = with_db(m.gain_margin);
  j["gain_reduction_margin"] = with_db(m.gain_reduction_margin);
  j["phase_margin"] = to_json(m.phase_margin, "deg", kDeg);
  nlohmann::json dm = to_json(m.delay_margin, "s", 1.0);
  dm["samples"] = m.delay_margin.status == MarginStatus::kFinite ? nlohmann::json(m.delay_margin.value / period_s)
                                                                 : nlohmann::json(nullptr);
  j["delay_margin"] = dm;
  j["gain_crossovers_rad_s"] = m.gain_crossovers_rad_s;
  j["phase_crossovers_rad_s"] = m.phase_crossovers_rad_s;
}

std::string measured_cell(const analysis::Margin& m, double scale, int precision = 2) {
  return cell(m, scale, "none", precision);
}

MeasuredReport measure_all(const MarginsSetup& s, const analysis::MeasurementOptions& mo, std::ostream& log) {
  const analysis::HoverMeasurementSetup& ms = s.measured;
  const double T = ms.simulation.plant.clock.period_s() * ms.simulation.controller_divider;
  MeasuredReport r;
  nlohmann::json& doc = r.doc;
  doc["method"] =
      "closed-loop simulation, sinusoid injected where the loop is broken, L identified over whole periods "
      "of the steady state";
  doc["controller"] = std::string(ms.controller.type());
  doc["mode"] = control::to_string(ms.controller.node.setpoint.mode);
  doc["trim_position_m"] = {ms.trim_p_W.x(), ms.trim_p_W.y(), ms.trim_p_W.z()};
  doc["broken_at"] = "the wrench U = M omega^2 the rotor command asks for, one component at a time";
  doc["amplitude_of_hover_rotor_speed"] = mo.amplitude;
  doc["frequencies"] = {{"grid_points", mo.points},
                        {"min_rad_s", mo.omega_min_rad_s},
                        {"max_rad_s", std::numbers::pi / T},
                        {"refinements_per_crossover", mo.refinements}};
  doc["steady_state"] = {{"settle_s", mo.settle_s},
                         {"window_min_s", mo.window_min_s},
                         {"tolerance", mo.tolerance},
                         {"max_s_per_frequency", mo.max_s}};
  doc["controller_period_s"] = T;
  doc["command_delay_ticks"] = ms.simulation.plant.command_delay_ticks;
  std::vector<std::string> notes = s.measured_notes;
  doc["loops"] = nlohmann::json::array();

  r.table += fmt::format("measured margins of {} (controller {})\n", s.source, ms.controller.type());
  r.table += fmt::format(
      "closed-loop simulation trimmed in hover at ({:g}, {:g}, {:g}) m ({} mode); loop broken at the wrench the "
      "rotor command asks for; sinusoids of {:g} x hover rotor speed at {} frequencies {:g}..{:.4g} rad/s "
      "(Nyquist), crossovers refined by bisection\n",
      ms.trim_p_W.x(), ms.trim_p_W.y(), ms.trim_p_W.z(), control::to_string(ms.controller.node.setpoint.mode),
      mo.amplitude, mo.points, mo.omega_min_rad_s, std::numbers::pi / T);
  r.table += fmt::format("{:<11} {:<30} {:>8} {:>9} {:>9} {:>8} {:>9} {:>8} {:>9} {:>6} {}\n", "loop", "broken at",
                         "GM [dB]", "w_pc", "GMlo[dB]", "PM [deg]", "w_gc", "DM [s]", "DM [smp]", "freqs", "status");
  for (const analysis::HoverAxis axis : {analysis::HoverAxis::kRoll, analysis::HoverAxis::kPitch,
                                         analysis::HoverAxis::kYaw, analysis::HoverAxis::kAltitude}) {
    const analysis::MeasuredLoop m = analysis::measure_loop(ms, axis, mo);
    const std::string name = analysis::to_string(axis);
    double simulated_s = 0.0;
    for (const auto& p : m.points) simulated_s += p.simulated_s;
    log << fmt::format("margins: measured {} at {} frequencies ({:.0f} s simulated)\n", name, m.points.size(),
                       simulated_s);
    r.all_in_hover = r.all_in_hover && m.problem.empty();
    nlohmann::json j;
    j["name"] = name;
    j["broken_at"] = analysis::broken_at(axis);
    j["amplitude"] = m.amplitude;
    j["stayed_in_hover"] = m.problem.empty();
    j["problem"] = m.problem.empty() ? nlohmann::json(nullptr) : nlohmann::json(m.problem);
    put_margins(j, m, T, measured_margin_json);
    j["unconverged_points"] = m.unconverged_points;
    nlohmann::json pts = nlohmann::json::array();
    double max_tilt = 0.0, max_rotor = 0.0;
    double unwrapped = 0.0, last_arg = 0.0;
    for (std::size_t i = 0; i < m.points.size(); ++i) {
      const analysis::MeasuredPoint& p = m.points[i];
      max_tilt = std::max(max_tilt, p.max_tilt_rad);
      max_rotor = std::max(max_rotor, p.max_rotor_deviation);
      const double arg = std::arg(p.L);
      unwrapped = i == 0 ? arg - 2 * std::numbers::pi * std::ceil(arg / (2 * std::numbers::pi))
                         : unwrapped + std::remainder(arg - last_arg, 2 * std::numbers::pi);
      last_arg = arg;
      const double mag_db = 20 * std::log10(std::abs(p.L));
      pts.push_back({{"omega_rad_s", p.omega_rad_s},
                     {"re", p.L.real()},
                     {"im", p.L.imag()},
                     {"magnitude_db", mag_db},
                     {"phase_deg", unwrapped * kDeg},
                     {"windows", p.windows},
                     {"periods_per_window", p.periods_per_window},
                     {"converged", p.converged}});
      r.csv += fmt::format("{},{:.9g},{:.9g},{:.9g},{:.9g},{:.9g},{}\n", name, p.omega_rad_s, p.L.real(), p.L.imag(),
                           mag_db, unwrapped * kDeg, p.converged ? 1 : 0);
    }
    j["max_tilt_rad"] = max_tilt;
    j["max_rotor_speed_deviation"] = max_rotor;
    j["points"] = pts;
    doc["loops"].push_back(j);
    if (m.unconverged_points > 0)
      notes.push_back(
          fmt::format("{}: {} frequencies did not reach steady state within {:g} s (their last window is used)", name,
                      m.unconverged_points, mo.max_s));

    analysis::Margin dms = m.delay_margin;
    if (dms.status == MarginStatus::kFinite) dms.value /= T;
    const std::string status = m.problem.empty() ? "in hover" : "LEFT HOVER: margins undefined";
    r.table += fmt::format("{:<11} {:<30} {:>8} {:>9} {:>9} {:>8} {:>9} {:>8} {:>9} {:>6} {}\n", name,
                           analysis::broken_at(axis), measured_cell(gain_db(m.gain_margin), 1.0),
                           freq_cell(m.gain_margin), measured_cell(gain_db(m.gain_reduction_margin), 1.0),
                           measured_cell(m.phase_margin, kDeg, 1), freq_cell(m.phase_margin),
                           measured_cell(m.delay_margin, 1.0, 3), measured_cell(dms, 1.0, 1), m.points.size(), status);
    if (!m.problem.empty()) notes.push_back(name + ": " + m.problem);
  }
  r.table +=
      "none: no crossing in the measured band; the measurement is small-signal: saturation and other "
      "nonlinearities at larger amplitudes are not in it\n";
  for (const std::string& n : notes) r.table += "note: " + n + '\n';
  doc["notes"] = notes;
  return r;
}

}  // namespace

MarginsPlan plan_margins(const std::string& path, const std::string& controller_type, bool measure,
                         const io::ScenarioResolvers& resolvers) {
  MarginsPlan p;
  MarginsSetup& s = p.setup;
  try {
    s = margins_setup(path, controller_type, resolvers);
    const controllers::PaperController* paper = controllers::paper_controller(s.controller);
    p.analytic = paper != nullptr;
    p.measured = !p.analytic || measure;
    if (std::string why = analysis::hover_trim_problem(s.plant); !why.empty()) throw std::invalid_argument(why);
    if (p.analytic) {
      s.notes.push_back(
          "the loops are linearised: the rotor clamp, the tilt limit and the integral bound are not "
          "in them");
      p.loops = analysis::hover_loops(s.plant, *paper, s.controller.node.setpoint.mode, s.timing);
    }
  } catch (const std::invalid_argument& e) {
    throw std::invalid_argument(
        fmt::format("{}cannot linearise about hover: {}", path.empty() ? "" : path + ": ", e.what()));
  }
  return p;
}

MarginsReport margins_report(const MarginsPlan& plan, const analysis::MeasurementOptions& measurement,
                             bool response_csv, std::ostream& log) {
  const MarginsSetup& s = plan.setup;
  const std::vector<analysis::HoverLoop>& loops = plan.loops;
  const bool analytic = plan.analytic;
  MarginsReport report;
  const analysis::LoopTiming& t = s.timing;
  const double T = t.tick_s * t.controller_divider;
  std::vector<analysis::LoopMargins> results;
  for (const auto& l : loops) results.push_back(analysis::analyse_margins(l.loop));

  nlohmann::json& doc = report.doc;
  doc["scenario"] = s.source;
  doc["controller"] = std::string(s.controller.type());
  if (analytic) doc["linearised_about"] = "level hover, still air";
  doc["mode"] = control::to_string(s.controller.node.setpoint.mode);
  doc["plant_period_s"] = t.tick_s;
  doc["controller_period_s"] = T;
  doc["command_delay_ticks"] = t.command_delay_ticks;
  doc["latency_ticks"] = {
      {"imu", t.imu_latency_ticks}, {"pose", t.pose_latency_ticks}, {"velocity", t.velocity_latency_ticks}};
  bool& all_stable = report.all_stable;
  std::string& table = report.table;
  if (analytic) {
    doc["notes"] = s.notes;
    doc["loops"] = nlohmann::json::array();
    for (std::size_t i = 0; i < loops.size(); ++i) {
      const analysis::LoopMargins& m = results[i];
      all_stable = all_stable && m.closed_loop_stable;
      nlohmann::json j;
      j["name"] = loops[i].name;
      j["broken_at"] = loops[i].broken_at;
      j["closed_loop_stable"] = m.closed_loop_stable;
      j["open_loop_unstable_poles"] = m.open_loop_unstable_poles;
      j["open_loop_marginal_poles"] = m.open_loop_marginal_poles;
      put_margins(j, m, T, margin_json);
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
    table +=
        "w_pc, w_gc [rad/s]: phase and gain crossover; GMlo: gain reduction margin (-inf: the gain may drop to 0)\n";
    for (const std::string& n : s.notes) table += "note: " + n + '\n';
  }

  if (plan.measured) {
    MeasuredReport r = measure_all(s, measurement, log);
    all_stable = all_stable && r.all_in_hover;
    if (analytic) table += '\n';
    table += r.table;
    if (!analytic) table += "w_pc, w_gc [rad/s]: phase and gain crossover; GMlo: gain reduction margin\n";
    doc["measured"] = r.doc;
    report.measured_response_csv = "loop,omega_rad_s,re,im,magnitude_db,phase_deg,converged\n" + r.csv;
  }

  if (analytic && response_csv) {
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
    report.frequency_response_csv = std::move(csv);
  }
  return report;
}

}  // namespace quadcosim::hosts
