// A reference trajectory: the flat outputs (position, its derivatives up to jerk, yaw and yaw rate)
// the controller tracks, as an analytic function of time. Kinds: periodic.hpp (circle, Lissajous,
// figure 8), waypoints.hpp (minimum snap / minimum jerk) and polynomial_file.hpp (Crazyswarm2 CSV).
#pragma once

#include <Eigen/Core>
#include <string>

namespace quadcosim::trajectory {

/// The flat outputs of a quadrotor at one instant, in the world frame (ENU, z up), SI units.
struct FlatOutput {
  Eigen::Vector3d p_W = Eigen::Vector3d::Zero();  ///< position [m]
  Eigen::Vector3d v_W = Eigen::Vector3d::Zero();  ///< velocity [m/s]
  Eigen::Vector3d a_W = Eigen::Vector3d::Zero();  ///< acceleration [m/s^2]
  Eigen::Vector3d j_W = Eigen::Vector3d::Zero();  ///< jerk [m/s^3]
  /// Yaw [rad], not wrapped (a polynomial yaw may leave (-pi, pi]); compare angles modulo 2 pi.
  double yaw_rad = 0;
  double yaw_rate_rad_s = 0;  ///< [rad/s]
};

class Trajectory {
 public:
  virtual ~Trajectory() = default;
  /// Exact (analytic) flat outputs at time t_s [s] since the start of the run; before its start
  /// and after its end, the trajectory holds its first / last point at rest (derivatives zero).
  virtual FlatOutput at(double t_s) const = 0;
  /// When the motion ends [s]; +inf for periodic ones.
  virtual double end_s() const = 0;
  /// One line, e.g. "circle r=2 m, period 10 s about (0, 0) at 5 m".
  virtual std::string describe() const = 0;
};

/// How a periodic trajectory points the vehicle: a fixed yaw, along the velocity, or at the centre.
enum class YawMode { kFixed, kTangent, kCentre };

}  // namespace quadcosim::trajectory
