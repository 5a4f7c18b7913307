// Periodic trajectories in a horizontal plane at constant altitude: circle, Lissajous curve, figure 8.
//
// All three are x = cx + Ax sin(wx s + phx), y = cy + Ay sin(wy s + phy), z = altitude, where s(t) is
// the time warp of the start: s = 0 before start_s (the start point held at rest); over the spin-up
// [start_s, start_s + ramp_s] the phase rate ds/dt rises from 0 to 1 as 10u^3 - 15u^4 + 6u^5
// (u = (t - start_s) / ramp_s), so velocity, acceleration and jerk are continuous (zero at start_s);
// afterwards s = t - start_s - ramp_s / 2 and the motion is the plain periodic one. ramp_s = 0 starts
// abruptly (a velocity step at start_s). Everything is analytic (chain rule through s(t)); end_s() is
// +inf.
//
// Yaw [rad]: kFixed a constant; kTangent atan2 of the path's tangent (the direction of travel; at
// rest, the direction it will move in), wrapped to (-pi, pi]; kCentre (circles only) facing the
// centre, wrapped to (-pi, pi]. Yaw rates are analytic.
#pragma once

#include <Eigen/Core>
#include <memory>

#include "trajectory/trajectory.hpp"

namespace quadcosim::trajectory {

struct CircleParams {
  Eigen::Vector2d centre_m = Eigen::Vector2d::Zero();  ///< (x, y) [m]
  double altitude_m = 1.0;                             ///< z [m]
  double radius_m = 1.0;                               ///< > 0
  double period_s = 10.0;                              ///< one lap at full speed, > 0
  bool clockwise = false;                              ///< seen from above (z up); default ccw
  double phase_rad = 0.0;                              ///< start point at centre + r (cos phase, sin phase)
  double start_s = 0.0;                                ///< [s]
  double ramp_s = 2.0;                                 ///< spin-up [s], >= 0
  YawMode yaw_mode = YawMode::kFixed;
  double yaw_rad = 0.0;  ///< kFixed only
};

struct LissajousParams {
  Eigen::Vector2d centre_m = Eigen::Vector2d::Zero();
  double altitude_m = 1.0;
  Eigen::Vector2d amplitude_m{1.0, 1.0};  ///< Ax, Ay >= 0 [m]
  Eigen::Vector2d period_s{10.0, 5.0};    ///< Tx, Ty > 0 [s] (w = 2 pi / T)
  Eigen::Vector2d phase_rad = Eigen::Vector2d::Zero();
  double start_s = 0.0;
  double ramp_s = 2.0;
  YawMode yaw_mode = YawMode::kFixed;  ///< kFixed or kTangent (a Lissajous curve may cross its centre)
  double yaw_rad = 0.0;
};

/// Figure 8: x = cx + Ax sin(w s), y = cy + Ay sin(2 w s), w = 2 pi / period; starts at the centre.
struct Figure8Params {
  Eigen::Vector2d centre_m = Eigen::Vector2d::Zero();
  double altitude_m = 1.0;
  Eigen::Vector2d amplitude_m{2.0, 1.0};
  double period_s = 10.0;  ///< one whole 8
  double start_s = 0.0;
  double ramp_s = 2.0;
  YawMode yaw_mode = YawMode::kFixed;  ///< kFixed or kTangent
  double yaw_rad = 0.0;
};

/// Each throws std::invalid_argument naming the parameter when one is not finite or out of range
/// (radius <= 0, period <= 0, amplitude < 0, ramp < 0, kCentre for a non-circle, kTangent with a zero
/// amplitude).
std::unique_ptr<Trajectory> make_circle(const CircleParams& p);
std::unique_ptr<Trajectory> make_lissajous(const LissajousParams& p);
std::unique_ptr<Trajectory> make_figure8(const Figure8Params& p);

}  // namespace quadcosim::trajectory
