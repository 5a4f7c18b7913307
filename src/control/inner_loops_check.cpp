// The inner loops' stability check (check_inner_loops, control/inner_loops.hpp): one-off design
// numerics (control/eigenvalues.hpp), compiled with the other design code (quadcosim_design,
// src/control/CMakeLists.txt) rather than with the per-tick loops.
#include "control/inner_loops.hpp"

#include <algorithm>
#include <cmath>
#include <sstream>

#include "control/eigenvalues.hpp"

namespace quadcosim::control {

std::string check_inner_loops(const InnerLoopParams& p, const model::VehicleParams& vehicle, double period_s) {
  std::ostringstream err;
  const double h = period_s;
  const double kw = p.rate_bandwidth_rad_s, kr = p.attitude_bandwidth_rad_s, kv = p.velocity_bandwidth_rad_s;
  if (!(h > 0.0) || !std::isfinite(h)) {
    err << "the plant period must be a positive number of seconds, got " << h;
    return err.str();
  }
  if (!(kw > 0.0 && kr > 0.0 && kv > 0.0 && std::isfinite(kw * kr * kv))) {
    return "inner loop bandwidths must be positive and finite";
  }
  if (kw * h > 1.0) {
    err << "inner.rate_bandwidth " << kw << " rad/s is too fast for the plant period " << h
        << " s: K_w * period must be <= 1 (at most " << 1.0 / h << " rad/s)";
    return err.str();
  }
  if (vehicle.motor.model != model::MotorModel::kIdeal) {
    const double tau = std::max(vehicle.motor.tau_up_s, vehicle.motor.tau_down_s);
    if (kw * tau > 1.0) {
      err << "inner.rate_bandwidth " << kw << " rad/s is too fast for the motors' time constant " << tau
          << " s: K_w * tau must be <= 1 (at most " << 1.0 / tau << " rad/s)";
      return err.str();
    }
  }
  // The linearised single axis under a zero-order hold over h: w' = u/J, theta' = w, v' = g theta, u/J
  // held over the tick. Attitude on the rate loop: state (theta, w); velocity on both: (v, theta, w).
  const double g = vehicle.gravity_m_s2;
  const double kwd = pole_matched(kw, h), kvd = pole_matched(kv, h);
  Eigen::Matrix2d att;
  att << 1.0, h, 0.0, 1.0;
  att += Eigen::Vector2d(h * h / 2.0, h) * Eigen::RowVector2d(-kwd * kr, -kwd);
  if (const double r = spectral_radius(att); !(r < 1.0)) {
    err << "inner.attitude_bandwidth " << kr << " rad/s is unstable on the rate loop (" << kw
        << " rad/s) at the plant period " << h << " s: spectral radius " << r << " >= 1";
    return err.str();
  }
  Eigen::Matrix3d vel;
  vel << 1.0, g * h, g * h * h / 2.0, 0.0, 1.0, h, 0.0, 0.0, 1.0;
  vel +=
      Eigen::Vector3d(g * h * h * h / 6.0, h * h / 2.0, h) * Eigen::RowVector3d(-kwd * kr * kvd / g, -kwd * kr, -kwd);
  if (const double r = spectral_radius(vel); !(r < 1.0)) {
    err << "inner.velocity_bandwidth " << kv << " rad/s is unstable on the attitude loop (" << kr
        << " rad/s) at the plant period " << h << " s: spectral radius " << r << " >= 1";
    return err.str();
  }
  return {};
}

}  // namespace quadcosim::control
