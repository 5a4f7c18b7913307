#include "sensors/gnss.hpp"

#include <limits>
#include <string>

namespace quadcosim::sensors {

Gnss::Gnss(const GnssConfig& config, model::Rng rng) : config_(config), plane_(config.site), rng_(rng) {}

std::string check(const GnssConfig& c) {
  if (c.outage_from_s == 0.0 && c.outage_to_s == 0.0) return "";
  if (!(c.outage_to_s > c.outage_from_s)) {
    return "outage_to_s (" + std::to_string(c.outage_to_s) + " s) is not after outage_from_s (" +
           std::to_string(c.outage_from_s) + " s): the outage is the window [outage_from_s, outage_to_s)";
  }
  return "";
}

GnssSample Gnss::measure(const model::Outputs& truth, double t_s) {
  GnssSample s;
  const double h = config_.horizontal_sigma_m, v = config_.vertical_sigma_m, w = config_.velocity_sigma_m_s;
  s.position_variance_enu = {h * h, h * h, v * v};
  s.velocity_variance = w * w;
  if (t_s < config_.fix_after_s || (t_s >= config_.outage_from_s && t_s < config_.outage_to_s)) {
    const double nan = std::numeric_limits<double>::quiet_NaN();
    s.position = {nan, nan, nan};
    s.velocity_W = Eigen::Vector3d::Constant(nan);
    return s;
  }
  s.fix = true;
  // Draws in a fixed order (east, north, up, then the velocity's three), so a seed gives the same
  // numbers whichever sigmas are zero.
  Eigen::Vector3d p = truth.p_W;
  const Eigen::Vector3d sigma_p(h, h, v);
  for (int i = 0; i < 3; ++i) p[i] += sigma_p[i] * rng_.normal();
  s.position = plane_.to_geodetic(p);
  s.velocity_W = truth.v_W;
  for (int i = 0; i < 3; ++i) s.velocity_W[i] += w * rng_.normal();
  return s;
}

}  // namespace quadcosim::sensors
