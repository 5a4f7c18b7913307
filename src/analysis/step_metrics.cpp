#include "analysis/step_metrics.hpp"

#include <cmath>

namespace quadcosim::analysis {

StepFigures step_figures(std::span<const double> t, std::span<const double> y, double t_step,
                         double target, const StepOptions& opt) {
  StepFigures f;
  f.target = target;
  std::size_t first = 0;
  while (first < t.size() && t[first] < t_step) ++first;
  if (t.size() != y.size() || t.size() - first < 2) return f;
  f.initial = y[first];
  const double step = target - f.initial;
  if (step == 0.0 || !std::isfinite(step)) return f;

  // Normalised response: 0 at the step, 1 at the target.
  auto s = [&](std::size_t i) { return (y[i] - f.initial) / step; };

  std::size_t peak = first;
  std::optional<double> t10, t90;
  for (std::size_t i = first; i < t.size(); ++i) {
    const double v = s(i);
    if (v > s(peak)) peak = i;
    if (!t10 && v >= 0.10) t10 = t[i];
    if (!t90 && v >= 0.90) t90 = t[i];
    if (!f.t95_s && v >= 0.95) f.t95_s = t[i] - t_step;
  }
  if (t10 && t90) f.rise_time_s = *t90 - *t10;
  const double over = s(peak) - 1.0;
  f.overshoot_pct = over > 0.0 ? over * 100.0 : 0.0;
  if (over > 0.0) f.peak_time_s = t[peak] - t_step;

  // Settling: the sample after the last one outside the band.
  std::optional<std::size_t> last_out;
  for (std::size_t i = first; i < t.size(); ++i) {
    if (std::abs(s(i) - 1.0) > opt.settling_band) last_out = i;
  }
  if (!last_out) {
    f.settling_time_2pct_s = 0.0;
  } else if (*last_out + 1 < t.size()) {
    f.settling_time_2pct_s = t[*last_out + 1] - t_step;
  }

  double sum = 0.0;
  std::size_t n = 0;
  const double window_start = t.back() - opt.final_window_s;
  for (std::size_t i = first; i < t.size(); ++i) {
    if (t[i] >= window_start) {
      sum += y[i];
      ++n;
    }
  }
  f.steady_state_error_pct = std::abs(sum / static_cast<double>(n) - target) / std::abs(step) * 100.0;
  return f;
}

const std::vector<std::string>& figure_names() {
  static const std::vector<std::string> names = {"overshoot_pct", "peak_time_s", "rise_time_s",
                                                 "t95_s", "settling_time_2pct_s",
                                                 "steady_state_error_pct"};
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

}  // namespace quadcosim::analysis
