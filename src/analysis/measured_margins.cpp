#include "analysis/measured_margins.hpp"

#include <fmt/format.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <optional>
#include <stdexcept>

#include "model/mixer.hpp"
#include "model/quadrotor.hpp"
#include "sim/controller_node.hpp"
#include "sim/inprocess_transport.hpp"
#include "sim/lockstep_core.hpp"
#include "sim/plant_node.hpp"

namespace quadcosim::analysis {

namespace {

constexpr double kPi = std::numbers::pi;
constexpr double kLeftHoverTilt_rad = 1.0;

double wrap_pi(double a) {  // to (-pi, pi]
  a = std::remainder(a, 2.0 * kPi);
  return a <= -kPi ? a + 2.0 * kPi : a;
}

/// The frequency actually injected: C whole periods in N whole controller samples, the window the
/// fewest periods lasting at least window_min_s. At Nyquist a period is 2 samples.
struct Window {
  double omega_rad_s;
  int periods;
  int samples;
  bool nyquist;
};

Window window_for(double omega_rad_s, double T, double window_min_s) {
  const double nyquist = kPi / T;
  if (!(omega_rad_s > 0.0) || omega_rad_s > nyquist * (1.0 + 1e-12))
    throw std::invalid_argument(
        fmt::format("measured margins: frequency {:g} rad/s is outside (0, {:g}] (the Nyquist frequency pi / T)",
                    omega_rad_s, nyquist));
  if (omega_rad_s >= nyquist * (1.0 - 1e-12)) {
    const int periods = std::max(1, static_cast<int>(std::ceil(window_min_s / (2.0 * T))));
    return {nyquist, periods, 2 * periods, true};
  }
  const double samples_per_period = 2.0 * kPi / (omega_rad_s * T);
  const int periods = std::max(1, static_cast<int>(std::ceil(window_min_s / (samples_per_period * T))));
  // At least 2 C + 1 samples: below Nyquist.
  const int samples = std::max(2 * periods + 1, static_cast<int>(std::lround(periods * samples_per_period)));
  return {2.0 * kPi * periods / (samples * T), periods, samples, false};
}

/// One closed-loop run with the loop broken on one axis: the controller publishes its rotor speeds
/// on a topic of its own; the break point turns them into the wrench they ask for, adds the
/// injected sinusoid to the axis's component, and hands the plant the rotor speeds of the sum on the
/// plant's command topic (where the scenario's command delay acts). Ticked by the lockstep loop in
/// the order of every in-process run (sim/simulation.hpp).
class InjectionRun {
 public:
  InjectionRun(const HoverMeasurementSetup& setup, HoverAxis axis, const Window& w, double amplitude)
      : cfg_(setup.simulation),
        topics_(sim::Topics::for_namespace(cfg_.ns)),
        controller_topics_(controller_topics(topics_)),
        plant_(transport_, topics_, setup.vehicle, plant_options(cfg_),
               model::Quadrotor(setup.vehicle).initial_state(setup.trim_p_W, 0.0, true)),
        controller_(transport_, controller_topics_, trimmed(setup)),
        mixer_(model::mixer_matrix4(setup.vehicle)),
        mixer_inverse_(mixer_.inverse()),
        index_(wrench_index(axis)),
        window_(w),
        amplitude_(amplitude),
        loop_({&plant_}, lockstep_options(cfg_), Hooks{this}, host_) {
    transport_.set_faults(cfg_.faults);
    period_s_ = cfg_.plant.clock.period_s() * cfg_.controller_divider;
    Eigen::Vector4d hover_U = Eigen::Vector4d::Zero();
    hover_U(0) = setup.vehicle.mass_kg * setup.vehicle.gravity_m_s2;
    omega_trim_ = (mixer_inverse_ * hover_U).cwiseMax(0.0).cwiseSqrt();
    command_pub_ = transport_.advertise<msg::Float64MultiArray>(topics_.motor_commands);
    transport_.subscribe<msg::Float64MultiArray>(controller_topics_.motor_commands,
                                                 [this](const msg::Float64MultiArray& m) { on_command(m); });
    controller_.set_log([](const std::string&) {});
    plant_.set_log([](const std::string&) {});
  }

  /// Runs the control samples [samples_run, until): false when the vehicle left hover.
  bool run_to(long until_sample) {
    const int div = cfg_.controller_divider;
    while (static_cast<long>(u_ctrl_.size()) < until_sample) {
      const sim::Tick k = next_tick_++;
      loop_.tick(k);
      if (k % div != 0) continue;
      if (u_ctrl_.size() != static_cast<std::size_t>(k / div + 1))
        throw std::runtime_error(fmt::format("measured margins: no rotor command at t = {:g} s", k * period_s_ / div));
      const model::State& x = plant_.state();
      const bool finite = x.p_W.allFinite() && x.v_W.allFinite() && x.q_WB.coeffs().allFinite() && x.w_B.allFinite();
      const double cos_tilt = finite ? x.q_WB.toRotationMatrix()(2, 2) : -1.0;
      const double tilt = std::acos(std::clamp(cos_tilt, -1.0, 1.0));
      max_tilt_ = std::max(max_tilt_, tilt);
      if (!finite || tilt > kLeftHoverTilt_rad) return false;
    }
    return true;
  }

  /// L over the samples [n0, n0 + window samples).
  std::complex<double> transfer(long n0) const {
    std::complex<double> c, d;
    for (long n = n0; n < n0 + window_.samples; ++n) {
      const std::complex<double> e = phasor(n);
      c += u_ctrl_[n] * e;
      d += injected_[n] * e;
    }
    return -c / (c + d);
  }

  double period_s() const { return period_s_; }
  double max_tilt() const { return max_tilt_; }
  double max_rotor_deviation() const { return max_rotor_deviation_; }

 private:
  struct Hooks {
    InjectionRun* r;
    static bool main_thread_due(sim::Tick /*k*/) { return false; }
    bool before_outputs(sim::Tick k) const {
      r->transport_.advance_to(k);
      return true;
    }
    void after_outputs(sim::Tick k) const {
      if (k % r->cfg_.controller_divider == 0) r->controller_.step(r->cfg_.plant.clock.ns(k), r->period_s_);
    }
    static void after_latch(std::size_t /*i*/, sim::Tick /*k*/) {}
    static void on_timeout(std::size_t /*i*/, sim::Tick /*k*/) {}
    static void on_resume(sim::Tick /*k*/) {}
    static bool status_awaited(std::size_t /*i*/) { return false; }
    static std::int64_t status_stamp_ns(std::size_t /*i*/) { return -1; }
  };

  static sim::Topics controller_topics(const sim::Topics& t) {
    sim::Topics c = t;
    c.motor_commands += "_before_break";
    return c;
  }
  static sim::PlantOptions plant_options(const sim::SimulationConfig& c) {
    sim::PlantOptions o = c.plant;
    o.publish_tf = false;
    return o;
  }
  static sim::LockstepOptions lockstep_options(const sim::SimulationConfig& c) {
    sim::LockstepOptions o;
    o.clock = c.plant.clock;
    o.duration_ticks = std::numeric_limits<sim::Tick>::max();
    o.controller_divider = c.controller_divider;
    return o;
  }
  static control::ControllerConfig trimmed(const HoverMeasurementSetup& s) {
    control::ControllerConfig c = s.controller;
    c.trajectory = nullptr;
    c.node.setpoint.p_des_W = s.trim_p_W;
    c.node.setpoint.roll_des_rad = c.node.setpoint.pitch_des_rad = c.node.setpoint.yaw_des_rad = 0.0;
    return c;
  }

  std::complex<double> phasor(long n) const {
    if (window_.nyquist) return {n % 2 == 0 ? 1.0 : -1.0, 0.0};
    return std::polar(1.0, -window_.omega_rad_s * period_s_ * static_cast<double>(n));
  }

  void on_command(const msg::Float64MultiArray& m) {
    const long n = static_cast<long>(u_ctrl_.size());
    Eigen::Vector4d omega = Eigen::Vector4d::Constant(std::numeric_limits<double>::quiet_NaN());
    if (m.data.size() == 4) omega = Eigen::Vector4d(m.data[0], m.data[1], m.data[2], m.data[3]);
    const Eigen::Vector4d omega_sq = omega.cwiseMax(0.0).cwiseProduct(omega.cwiseMax(0.0));
    const double u_ctrl = (mixer_ * omega_sq)(index_);
    const double d = window_.nyquist ? amplitude_ * (n % 2 == 0 ? 1.0 : -1.0)
                                     : amplitude_ * std::sin(window_.omega_rad_s * period_s_ * static_cast<double>(n));
    u_ctrl_.push_back(u_ctrl);
    injected_.push_back(d);
    max_rotor_deviation_ =
        std::max(max_rotor_deviation_, ((omega - omega_trim_).cwiseAbs().cwiseQuotient(omega_trim_)).maxCoeff());
    // The plant gets the rotor speeds whose wrench is the controller's plus d on this axis.
    const Eigen::Vector4d plant_sq = (omega_sq + mixer_inverse_.col(index_) * d).cwiseMax(0.0);
    out_ = m;
    out_.data.assign(4, 0.0);
    for (int i = 0; i < 4; ++i) out_.data[i] = std::isfinite(omega(i)) ? std::sqrt(plant_sq(i)) : omega(i);
    command_pub_.publish(out_);
  }

  sim::SimulationConfig cfg_;
  sim::Topics topics_, controller_topics_;
  sim::InProcessTransport transport_;
  sim::PlantNode plant_;
  sim::ControllerNode controller_;
  Eigen::Matrix4d mixer_, mixer_inverse_;
  int index_;
  Window window_;
  double amplitude_;
  double period_s_ = 0.0;
  Eigen::Vector4d omega_trim_;
  sim::Publisher<msg::Float64MultiArray> command_pub_;
  msg::Float64MultiArray out_;
  std::vector<double> u_ctrl_, injected_;  ///< per control sample
  double max_tilt_ = 0.0, max_rotor_deviation_ = 0.0;
  sim::Tick next_tick_ = 0;
  sim::SynchronousHost host_;
  sim::LockstepCore<sim::PlantNode, Hooks, sim::SynchronousHost, true> loop_;
};

/// The amplitude on `axis` [N or N m] that moves no rotor by more than `fraction` of its hover speed
/// (to first order: d(omega^2) = 2 omega d(omega)).
double axis_amplitude(const model::VehicleParams& v, HoverAxis axis, double fraction) {
  const Eigen::Matrix4d mi = model::mixer_matrix4(v).inverse();
  Eigen::Vector4d hover_U = Eigen::Vector4d::Zero();
  hover_U(0) = v.mass_kg * v.gravity_m_s2;
  const Eigen::Vector4d omega_sq = mi * hover_U;
  double amplitude = std::numeric_limits<double>::infinity();
  for (int j = 0; j < 4; ++j) {
    const double per_unit = std::abs(mi(j, wrench_index(axis)));  // d(omega_j^2) per unit of U_i
    if (per_unit > 0.0) amplitude = std::min(amplitude, 2.0 * fraction * omega_sq(j) / per_unit);
  }
  return amplitude;
}

// Crossings between two neighbouring points, the phase of q unwrapped against p's.
struct Segment {
  double x0, x1;  ///< ln omega
  double g0, g1;  ///< ln |L|
  double p0, p1;  ///< phase [rad], continuous from p0
};
Segment segment(const MeasuredPoint& a, const MeasuredPoint& b, double phase_a) {
  return {std::log(a.omega_rad_s),
          std::log(b.omega_rad_s),
          std::log(std::abs(a.L)),
          std::log(std::abs(b.L)),
          phase_a,
          phase_a + wrap_pi(std::arg(b.L) - std::arg(a.L))};
}
bool gain_crossing(const Segment& s) { return (s.g0 > 0.0) != (s.g1 > 0.0); }
/// The line -pi + 2 pi k the phase crosses strictly inside the segment, if any.
std::optional<double> phase_crossing(const Segment& s) {
  const double k0 = std::floor((s.p0 + kPi) / (2.0 * kPi)), k1 = std::floor((s.p1 + kPi) / (2.0 * kPi));
  if (k0 == k1) return std::nullopt;
  return -kPi + 2.0 * kPi * std::max(k0, k1);
}

}  // namespace

const char* to_string(HoverAxis axis) {
  switch (axis) {
    case HoverAxis::kRoll: return "roll";
    case HoverAxis::kPitch: return "pitch";
    case HoverAxis::kYaw: return "yaw";
    case HoverAxis::kAltitude: return "altitude";
  }
  return "?";
}

int wrench_index(HoverAxis axis) {
  switch (axis) {
    case HoverAxis::kAltitude: return 0;
    case HoverAxis::kRoll: return 1;
    case HoverAxis::kPitch: return 2;
    case HoverAxis::kYaw: return 3;
  }
  return 0;
}

std::string broken_at(HoverAxis axis) {
  switch (axis) {
    case HoverAxis::kRoll: return "U2 roll torque [N m]";
    case HoverAxis::kPitch: return "U3 pitch torque [N m]";
    case HoverAxis::kYaw: return "U4 yaw torque [N m]";
    case HoverAxis::kAltitude: return "U1 collective thrust [N]";
  }
  return "?";
}

MeasuredPoint measure_point(const HoverMeasurementSetup& setup, HoverAxis axis, double omega_rad_s,
                            const MeasurementOptions& o, bool& left_hover) {
  const double T = setup.simulation.plant.clock.period_s() * setup.simulation.controller_divider;
  const Window w = window_for(omega_rad_s, T, o.window_min_s);
  InjectionRun run(setup, axis, w, axis_amplitude(setup.vehicle, axis, o.amplitude));
  MeasuredPoint p;
  p.omega_rad_s = w.omega_rad_s;
  p.periods_per_window = w.periods;
  const long first = std::lround(std::ceil(o.settle_s / T));
  const long max_samples = std::max<long>(first + 2L * w.samples, std::lround(o.max_s / T));
  left_hover = false;
  std::complex<double> previous;
  for (long n0 = first; n0 + w.samples <= max_samples; n0 += w.samples) {
    if (!run.run_to(n0 + w.samples)) {
      left_hover = true;
      break;
    }
    const std::complex<double> L = run.transfer(n0);
    ++p.windows;
    p.simulated_s = static_cast<double>(n0 + w.samples) * T;
    const bool agrees = p.windows > 1 && std::abs(L - previous) <= o.tolerance * std::abs(L);
    p.L = previous = L;
    if (agrees) {
      p.converged = true;
      break;
    }
  }
  p.max_tilt_rad = run.max_tilt();
  p.max_rotor_deviation = run.max_rotor_deviation();
  return p;
}

void margins_from_points(MeasuredLoop& loop, double period_s) {
  loop.gain_crossovers_rad_s.clear();
  loop.phase_crossovers_rad_s.clear();
  loop.gain_margin = loop.gain_reduction_margin = loop.phase_margin = loop.delay_margin = Margin{};
  if (!loop.problem.empty() || loop.points.empty()) return;
  const double nyquist = kPi / period_s;
  std::vector<std::pair<double, double>> phase_x;  // (omega, |L|) at each phase crossover
  std::vector<std::pair<double, double>> gain_x;   // (omega, phase margin) at each gain crossover
  double phase = std::arg(loop.points[0].L);
  for (std::size_t i = 0; i + 1 < loop.points.size(); ++i) {
    const MeasuredPoint& a = loop.points[i];
    const MeasuredPoint& b = loop.points[i + 1];
    const Segment s = segment(a, b, phase);
    phase = s.p1;
    if (gain_crossing(s)) {
      const double t = s.g0 / (s.g0 - s.g1);
      gain_x.emplace_back(std::exp(s.x0 + t * (s.x1 - s.x0)), wrap_pi(s.p0 + t * (s.p1 - s.p0) + kPi));
    }
    const bool ends_at_nyquist = b.omega_rad_s >= nyquist * (1.0 - 1e-12);
    // At Nyquist L is real: a crossing that lands there is the end point's, below.
    if (const auto line = phase_crossing(s); line && !(ends_at_nyquist && std::abs(*line - s.p1) < 1e-9)) {
      const double t = (*line - s.p0) / (s.p1 - s.p0);
      phase_x.emplace_back(std::exp(s.x0 + t * (s.x1 - s.x0)), std::exp(s.g0 + t * (s.g1 - s.g0)));
    }
  }
  const MeasuredPoint& last = loop.points.back();
  if (last.omega_rad_s >= nyquist * (1.0 - 1e-12) && last.L.real() < 0.0)
    phase_x.emplace_back(last.omega_rad_s, std::abs(last.L));

  for (const auto& [w, m] : phase_x) {
    loop.phase_crossovers_rad_s.push_back(w);
    const double factor = 1.0 / m;
    if (factor > 1.0 && (loop.gain_margin.status != MarginStatus::kFinite || factor < loop.gain_margin.value))
      loop.gain_margin = {MarginStatus::kFinite, factor, w};
    if (factor < 1.0 &&
        (loop.gain_reduction_margin.status != MarginStatus::kFinite || factor > loop.gain_reduction_margin.value))
      loop.gain_reduction_margin = {MarginStatus::kFinite, factor, w};
  }
  for (const auto& [w, pm] : gain_x) {
    loop.gain_crossovers_rad_s.push_back(w);
    if (loop.phase_margin.status != MarginStatus::kFinite || std::abs(pm) < std::abs(loop.phase_margin.value))
      loop.phase_margin = {MarginStatus::kFinite, pm, w};
    const double dm = std::fmod(pm + 2.0 * kPi, 2.0 * kPi) / w;
    if (loop.delay_margin.status != MarginStatus::kFinite || dm < loop.delay_margin.value)
      loop.delay_margin = {MarginStatus::kFinite, dm, w};
  }
  // No crossing in the measured band: "none" (kInfinite), not a number.
  for (Margin* m : {&loop.gain_margin, &loop.gain_reduction_margin, &loop.phase_margin, &loop.delay_margin}) {
    if (m->status != MarginStatus::kFinite) m->status = MarginStatus::kInfinite;
  }
  loop.unconverged_points = static_cast<int>(
      std::count_if(loop.points.begin(), loop.points.end(), [](const MeasuredPoint& p) { return !p.converged; }));
}

MeasuredLoop measure_loop(const HoverMeasurementSetup& setup, HoverAxis axis, const MeasurementOptions& o,
                          const std::function<void(HoverAxis, const MeasuredPoint&)>& progress) {
  if (!(o.amplitude > 0.0) || !(o.omega_min_rad_s > 0.0) || o.points < 2 || o.refinements < 0 ||
      !(o.window_min_s > 0.0) || !(o.tolerance > 0.0) || !(o.settle_s >= 0.0) || !(o.max_s > 0.0))
    throw std::invalid_argument(
        "measured margins: amplitude, lowest frequency, window, tolerance and time must be "
        "positive, with at least 2 frequencies");
  const double T = setup.simulation.plant.clock.period_s() * setup.simulation.controller_divider;
  const double nyquist = kPi / T;
  if (!(o.omega_min_rad_s < nyquist))
    throw std::invalid_argument(
        fmt::format("measured margins: the lowest frequency {:g} rad/s is not below the Nyquist frequency {:g} rad/s",
                    o.omega_min_rad_s, nyquist));
  MeasuredLoop loop;
  loop.axis = axis;
  loop.amplitude = axis_amplitude(setup.vehicle, axis, o.amplitude);
  auto measure = [&](double w) -> std::optional<MeasuredPoint> {
    bool left = false;
    MeasuredPoint p = measure_point(setup, axis, w, o, left);
    if (progress) progress(axis, p);
    if (left) {
      loop.problem = fmt::format(
          "the closed loop left hover (tilt above {:g} rad or a non-finite state) with {:g} injected at {:.4g} rad/s: "
          "unstable, or not small-signal at this amplitude",
          kLeftHoverTilt_rad, loop.amplitude, p.omega_rad_s);
      return std::nullopt;
    }
    return p;
  };
  for (int j = 0; j < o.points; ++j) {
    const double w = j + 1 == o.points ? nyquist
                                       : o.omega_min_rad_s * std::pow(nyquist / o.omega_min_rad_s,
                                                                      static_cast<double>(j) / (o.points - 1));
    const auto p = measure(w);
    if (!p) return loop;
    if (!loop.points.empty() && p->omega_rad_s <= loop.points.back().omega_rad_s) continue;  // same window twice
    loop.points.push_back(*p);
  }

  // Bisect (geometrically) every grid interval holding a crossing, with measurements.
  std::vector<MeasuredPoint> extra;
  double phase = std::arg(loop.points[0].L);
  for (std::size_t i = 0; i + 1 < loop.points.size(); ++i) {
    MeasuredPoint a = loop.points[i], b = loop.points[i + 1];
    const Segment s = segment(a, b, phase);
    const double phase_b = s.p1;
    const bool at_nyquist_end = b.omega_rad_s >= nyquist * (1.0 - 1e-12);
    const auto line = phase_crossing(s);
    const bool wanted_gain = gain_crossing(s);
    const bool wanted_phase = line && !(at_nyquist_end && std::abs(*line - s.p1) < 1e-9);
    if (wanted_gain || wanted_phase) {
      // Gain and phase crossings are chased separately: each keeps the half holding it.
      for (const bool chase_gain : {true, false}) {
        if (chase_gain ? !wanted_gain : !wanted_phase) continue;
        MeasuredPoint lo = a, hi = b;
        double phase_lo = phase;
        for (int r = 0; r < o.refinements; ++r) {
          const double mid_w = std::sqrt(lo.omega_rad_s * hi.omega_rad_s);
          const Window win = window_for(std::min(mid_w, nyquist), T, o.window_min_s);
          if (!(win.omega_rad_s > lo.omega_rad_s && win.omega_rad_s < hi.omega_rad_s)) break;
          const auto p = measure(mid_w);
          if (!p) return loop;
          extra.push_back(*p);
          const Segment left = segment(lo, *p, phase_lo);
          const bool in_left = chase_gain ? gain_crossing(left) : phase_crossing(left).has_value();
          if (in_left) {
            hi = *p;
          } else {
            lo = *p;
            phase_lo = left.p1;
          }
        }
      }
    }
    phase = phase_b;
  }
  loop.points.insert(loop.points.end(), extra.begin(), extra.end());
  std::sort(loop.points.begin(), loop.points.end(),
            [](const MeasuredPoint& x, const MeasuredPoint& y) { return x.omega_rad_s < y.omega_rad_s; });
  loop.points.erase(
      std::unique(loop.points.begin(), loop.points.end(),
                  [](const MeasuredPoint& x, const MeasuredPoint& y) { return x.omega_rad_s == y.omega_rad_s; }),
      loop.points.end());
  margins_from_points(loop, T);
  return loop;
}

}  // namespace quadcosim::analysis
