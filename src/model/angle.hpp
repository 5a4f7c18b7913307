// Angle wrapping, header-only: the model, the controller and the analysis (which links no model
// library) share one definition.
#pragma once

#include <cmath>
#include <numbers>

namespace quadcosim::model {

/// Wraps an angle to (-pi, pi] [rad]; an angle already there is returned unchanged, a non-finite
/// one as it is.
inline double wrap_pi(double angle_rad) {
  constexpr double pi = std::numbers::pi;
  // Already in (-pi, pi]: std::remainder would return it unchanged (quotient rounds to 0).
  if (angle_rad > -pi && angle_rad <= pi) return angle_rad;
  if (!std::isfinite(angle_rad)) return angle_rad;
  const double a = std::remainder(angle_rad, 2.0 * pi);  // in [-pi, pi]
  return a <= -pi ? a + 2.0 * pi : a;
}

}  // namespace quadcosim::model
