#include "analysis/tracking.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <stdexcept>

#include "model/angle.hpp"

namespace quadcosim::analysis {

namespace {
// Sum of squares, maximum and count of a non-negative error.
struct Accumulator {
  double sum_sq = 0.0, max = 0.0;
  std::size_t n = 0;
  void add(double e) {
    sum_sq += e * e;
    max = std::max(max, e);
    ++n;
  }
  double rms() const { return std::sqrt(sum_sq / static_cast<double>(n)); }
};
}  // namespace

const std::vector<std::string>& tracking_figure_names() {
  static const std::vector<std::string> names = {
      "position_rmse_m",   "position_max_m", "x_rmse_m", "x_max_m",      "y_rmse_m",
      "y_max_m",           "z_rmse_m",       "z_max_m",  "yaw_rmse_rad", "attitude_error_rmse",
      "attitude_error_max"};
  return names;
}

TrackingFigures tracking_figures(const TrackingSeries& s, double after_s, double reference_period_s) {
  const std::size_t n = s.t_s.size();
  if (!(reference_period_s >= 0.0) || !std::isfinite(reference_period_s)) {
    throw std::invalid_argument("tracking_figures: reference_period_s must be finite and >= 0");
  }
  // Sample times are tick * period: a multiple of the controller period to within rounding.
  auto at_reference_step = [&](double t) {
    if (reference_period_s == 0.0) return true;
    const double k = t / reference_period_s;
    return std::abs(k - std::round(k)) <= 1e-6;
  };
  for (const auto column : {s.x_des, s.y_des, s.z_des, s.yaw_des, s.x, s.y, s.z, s.yaw}) {
    if (column.size() != n) throw std::invalid_argument("tracking_figures: a column differs in length from t");
  }
  if (!s.attitude_error.empty() && s.attitude_error.size() != n) {
    throw std::invalid_argument("tracking_figures: the attitude error column differs in length from t");
  }
  Accumulator norm, yaw, psi;
  std::array<Accumulator, 3> axis;
  const std::array<std::span<const double>, 3> ref = {s.x_des, s.y_des, s.z_des}, got = {s.x, s.y, s.z};
  for (std::size_t i = 0; i < n; ++i) {
    if (!(s.t_s[i] >= after_s) || !at_reference_step(s.t_s[i])) continue;
    std::array<double, 3> e{};
    bool finite = true;
    for (int k = 0; k < 3; ++k) {
      e[static_cast<std::size_t>(k)] = ref[static_cast<std::size_t>(k)][i] - got[static_cast<std::size_t>(k)][i];
      finite = finite && std::isfinite(e[static_cast<std::size_t>(k)]);
    }
    if (!finite) continue;  // no reference recorded yet (or open loop)
    norm.add(std::sqrt(e[0] * e[0] + e[1] * e[1] + e[2] * e[2]));
    for (std::size_t k = 0; k < 3; ++k) axis[k].add(std::abs(e[k]));
    const double e_yaw = model::wrap_pi(s.yaw_des[i] - s.yaw[i]);
    if (std::isfinite(e_yaw)) yaw.add(std::abs(e_yaw));
    if (!s.attitude_error.empty() && std::isfinite(s.attitude_error[i])) psi.add(std::abs(s.attitude_error[i]));
  }
  TrackingFigures f;
  f.samples = norm.n;
  if (norm.n > 0) {
    f.values["position_rmse_m"] = norm.rms();
    f.values["position_max_m"] = norm.max;
    const char* names[] = {"x", "y", "z"};
    for (std::size_t k = 0; k < 3; ++k) {
      f.values[std::string(names[k]) + "_rmse_m"] = axis[k].rms();
      f.values[std::string(names[k]) + "_max_m"] = axis[k].max;
    }
  }
  if (yaw.n > 0) f.values["yaw_rmse_rad"] = yaw.rms();
  if (psi.n > 0) {
    f.values["attitude_error_rmse"] = psi.rms();
    f.values["attitude_error_max"] = psi.max;
  }
  return f;
}

}  // namespace quadcosim::analysis
