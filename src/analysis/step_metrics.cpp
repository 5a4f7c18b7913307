#include "analysis/step_metrics.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>

#include <fmt/format.h>

#include "model/angle.hpp"

namespace quadcosim::analysis {

std::vector<double> unwrap_angle(std::span<const double> y) {
  std::vector<double> out(y.begin(), y.end());
  for (std::size_t i = 1; i < out.size(); ++i) out[i] = out[i - 1] + model::wrap_pi(y[i] - y[i - 1]);
  return out;
}

StepFigures step_figures(std::span<const double> t, std::span<const double> y_in, double t_step, double target,
                         const StepOptions& opt) {
  StepFigures f;
  f.target = target;
  if (t.size() != y_in.size()) return f;
  std::size_t first = 0;
  while (first < t.size() && t[first] < t_step) ++first;
  if (first < t.size()) f.post_step_s = t.back() - t_step;
  if (t.size() - first < 2) return f;  // too short: nothing to judge
  f.initial = y_in[first];

  // The response judged: from the step on, unwrapped for an angle so that it starts at y[first].
  std::vector<double> y(y_in.begin() + static_cast<std::ptrdiff_t>(first), y_in.end());
  if (opt.angle) y = unwrap_angle(y);
  const std::span<const double> tt = t.subspan(first);
  f.step = opt.angle ? model::wrap_pi(target - f.initial) : target - f.initial;
  if (!std::isfinite(f.step)) return f;
  const double goal = f.initial + f.step;  // the target on the unwrapped response
  const double post_s = f.post_step_s;
  f.final_window_s = std::max(opt.final_window_fraction * post_s, opt.final_window_min_s);
  if (std::abs(f.step) <= kZeroStep) {
    f.verdict = StepVerdict::kZeroStep;
    return f;
  }

  // Normalised response: 0 at the step, 1 at the target.
  auto s = [&](std::size_t i) { return (y[i] - f.initial) / f.step; };
  std::size_t peak = 0;
  std::optional<double> t10, t90;
  for (std::size_t i = 0; i < tt.size(); ++i) {
    const double v = s(i);
    if (v > s(peak)) peak = i;
    if (!t10 && v >= 0.10) t10 = tt[i];
    if (!t90 && v >= 0.90) t90 = tt[i];
    if (!f.t95_s && v >= 0.95) f.t95_s = tt[i] - t_step;
  }
  if (t10 && t90) f.rise_time_s = *t90 - *t10;
  const double over = s(peak) - 1.0;
  f.overshoot_pct = over > 0.0 ? over * 100.0 : 0.0;
  if (over > 0.0) f.peak_time_s = tt[peak] - t_step;

  if (post_s < f.final_window_s) {  // the final window does not fit after the step
    f.verdict = StepVerdict::kTooShort;
    return f;
  }
  const double window_start = tt.back() - f.final_window_s;
  double sum = 0.0;
  std::size_t n = 0;
  bool window_inside = true;
  std::optional<std::size_t> last_out;
  for (std::size_t i = 0; i < tt.size(); ++i) {
    const bool out = !(std::abs(s(i) - 1.0) <= opt.settling_band);  // NaN is outside
    if (out) last_out = i;
    if (tt[i] >= window_start) {
      sum += y[i];
      ++n;
      window_inside = window_inside && !out;
    }
  }
  f.steady_state_error_pct = std::abs(sum / static_cast<double>(n) - goal) / std::abs(f.step) * 100.0;
  if (!window_inside) {
    f.verdict = StepVerdict::kNotSettled;
    return f;
  }
  f.verdict = StepVerdict::kSettled;
  // The last entry into the band: the sample after the last one outside it (the window is inside,
  // so that sample exists and lies at or before the window's start).
  f.settling_time_2pct_s = last_out ? tt[*last_out + 1] - t_step : 0.0;
  return f;
}

const std::vector<std::string>& figure_names() {
  static const std::vector<std::string> names = {"overshoot_pct", "peak_time_s",          "rise_time_s",
                                                 "t95_s",         "settling_time_2pct_s", "steady_state_error_pct"};
  return names;
}

std::optional<double> figure(const StepFigures& f, const std::string& name) {
  if (name == "overshoot_pct") return f.overshoot_pct;
  if (name == "peak_time_s") return f.peak_time_s;
  if (name == "rise_time_s") return f.rise_time_s;
  if (name == "t95_s") return f.t95_s;
  if (name == "settling_time_2pct_s") return f.settling_time_2pct_s;
  if (name == "steady_state_error_pct") return f.steady_state_error_pct;
  return std::nullopt;
}

const char* to_string(StepVerdict v) {
  switch (v) {
    case StepVerdict::kSettled: return "settled";
    case StepVerdict::kNotSettled: return "not settled";
    case StepVerdict::kTooShort: return "too short to judge";
    case StepVerdict::kZeroStep: return "zero-size step";
  }
  return "?";
}

std::string unjudgeable_reason(const StepFigures& f, const std::string& name, const StepOptions& opt) {
  const bool settling = name == "settling_time_2pct_s" || name == "steady_state_error_pct";
  switch (f.verdict) {
    case StepVerdict::kSettled: return "";
    case StepVerdict::kNotSettled:
      if (!settling) return "";
      return fmt::format("the run ended before settling: not inside the {:g} % band over the final {:g} s window",
                         opt.settling_band * 100.0, f.final_window_s);
    case StepVerdict::kTooShort:
      return fmt::format("the run is too short to judge: {:g} s after the step, the final window needs {:g} s",
                         f.post_step_s, opt.final_window_min_s);
    case StepVerdict::kZeroStep:
      return fmt::format("zero-size step: the setpoint equals the value at the step ({:g}), no step figure exists",
                         f.initial);
  }
  return "";
}

}  // namespace quadcosim::analysis
