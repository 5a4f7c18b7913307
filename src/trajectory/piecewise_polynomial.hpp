// A piecewise polynomial in time for x, y, z and yaw: what waypoint plans and polynomial files become.
#pragma once

#include <Eigen/Core>
#include <string>
#include <vector>

#include "trajectory/trajectory.hpp"

namespace quadcosim::trajectory {

class PiecewisePolynomial : public Trajectory {
 public:
  static constexpr int kCoefficients = 8;  ///< degree 7 at most (the Crazyflie's layout)
  /// Rows x [m], y [m], z [m], yaw [rad]; column i is the coefficient of tau^i, tau [s] the time since
  /// the segment's start.
  using Coefficients = Eigen::Matrix<double, 4, kCoefficients>;
  struct Segment {
    double duration_s = 0;
    Coefficients c = Coefficients::Zero();
  };

  /// Segments one after the other from start_s [s]. `label` starts describe(). Throws
  /// std::invalid_argument when there is no segment, a duration is not finite and > 0, a coefficient
  /// or start_s is not finite.
  PiecewisePolynomial(std::vector<Segment> segments, double start_s = 0, std::string label = "polynomial");

  /// Position, velocity, acceleration, jerk, yaw and yaw rate from the segment that holds t_s (on a
  /// join, the later one). Before start_s: the first point at rest; from end_s() on: the last point at
  /// rest (a file whose ends are not at rest jumps there).
  FlatOutput at(double t_s) const override;
  double end_s() const override { return end_s_; }
  /// e.g. "min_snap through 4 waypoints: 3 segments from 0 s to 12 s".
  std::string describe() const override;

  /// d^order/dt^order (order 0..7) of (x, y, z, yaw) at t_s, with t_s clamped to [start_s, end_s];
  /// on a join, the later segment (`left` true: the earlier one). For checks of smoothness.
  Eigen::Vector4d derivative(double t_s, int order, bool left = false) const;

  const std::vector<Segment>& segments() const { return segments_; }
  double start_s() const { return start_s_; }
  /// What describe() starts with ("polynomial file fig8.csv", "min_snap through 4 waypoints").
  const std::string& label() const { return label_; }

  /// d^order/dtau^order of one segment's polynomials at tau [s] (Horner); zero for order > 7.
  static Eigen::Vector4d evaluate(const Coefficients& c, double tau_s, int order);

 private:
  /// Index of the segment holding t (clamped), and t's time within it.
  std::size_t locate(double t_s, bool left, double& tau_s) const;

  std::vector<Segment> segments_;
  std::vector<double> starts_s_;  ///< absolute start of each segment
  double start_s_ = 0, end_s_ = 0;
  std::string label_;
};

}  // namespace quadcosim::trajectory
