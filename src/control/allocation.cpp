#include "control/allocation.hpp"

#include <algorithm>
#include <cmath>

namespace quadcosim::control {

Allocation allocate(const Eigen::Matrix4d& mixer_inverse, const Eigen::Vector4d& U, double omega_min_rad_s,
                    double omega_max_rad_s) {
  const Eigen::Vector4d omega_sq = mixer_inverse * U;
  const double lo = omega_min_rad_s * omega_min_rad_s;
  const double hi = omega_max_rad_s * omega_max_rad_s;
  Allocation out;
  for (int i = 0; i < 4; ++i) {
    // A non-finite demand (only possible from a non-finite U) is treated as the lowest speed.
    const double demand = std::isfinite(omega_sq[i]) ? omega_sq[i] : lo;
    const double w2 = std::clamp(demand, lo, hi);
    out.saturated[i] = !(omega_sq[i] >= lo && omega_sq[i] <= hi);
    out.omega_rad_s[i] = std::sqrt(std::max(0.0, w2));
  }
  return out;
}

}  // namespace quadcosim::control
