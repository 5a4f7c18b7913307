// Smooth piecewise polynomials through timed waypoints: minimum snap (degree 7) or minimum jerk
// (degree 5), and a minimum-jerk yaw.
#pragma once

#include <Eigen/Core>
#include <optional>
#include <vector>

#include "trajectory/piecewise_polynomial.hpp"

namespace quadcosim::trajectory {

struct Waypoint {
  double t_s = 0;                                 ///< when to be there [s]
  Eigen::Vector3d p_W = Eigen::Vector3d::Zero();  ///< [m]
  std::optional<double> yaw_rad;                  ///< absent: the previous waypoint's yaw (0 for the first)
};

enum class WaypointMethod {
  kMinSnap,  ///< degree 7, minimises the integral of |d^4 p/dt^4|^2; v, a, jerk zero at both ends
  kMinJerk,  ///< degree 5, minimises the integral of |d^3 p/dt^3|^2; v, a zero at both ends
};

/// The polynomial through `waypoints` (x, y, z each independently) that minimises the integral of
/// the squared k-th derivative (k = 4 snap, k = 3 jerk) over [t_0, t_N-1], with derivatives 1..k-1
/// zero at both ends (rest to rest). Method: the minimiser is the spline of degree 2k - 1 whose
/// derivatives 1..2k-2 are continuous at every interior waypoint (the Euler-Lagrange condition of the
/// cost; for k = 2 this is the clamped cubic spline), so the closed form is one square sparse linear
/// system in the coefficients (per segment, in normalised time): interpolation at both ends of every
/// segment, continuity of derivatives 1..2k-2 at the joins, the end conditions. Yaw: the same with
/// k = 3 (minimum jerk) through the waypoint yaws, unwrapped so each step is the shorter way round.
/// Before t_0 and after t_N-1 the ends are held at rest. Throws std::invalid_argument for fewer than
/// two waypoints, non-finite values, or times not strictly increasing.
PiecewisePolynomial plan_waypoints(const std::vector<Waypoint>& waypoints, WaypointMethod method);

/// "min_snap" or "min_jerk".
const char* method_name(WaypointMethod method);

}  // namespace quadcosim::trajectory
