// Trajectory-tracking figures of a recorded run (docs/outputs.md, "Tracking"): how far the measured
// position, yaw and attitude stay from the reference the controller tracked, over t >= after_s.
#pragma once

#include <cstddef>
#include <map>
#include <span>
#include <string>
#include <vector>

namespace quadcosim::analysis {

/// The recorded columns of a run (one entry per sample, all the same length as t_s): the reference
/// (x_des, y_des, z_des [m], yaw_des [rad]), the measured x, y, z [m] and yaw [rad], and the
/// controller's attitude error Psi = 1/2 tr(I - R_d^T R) (NaN where it has none; may be empty).
struct TrackingSeries {
  std::span<const double> t_s;
  std::span<const double> x_des, y_des, z_des, yaw_des;
  std::span<const double> x, y, z, yaw;
  std::span<const double> attitude_error;
};

/// The figures by name, in tracking_figure_names() order; errors are reference minus measured:
///   position_rmse_m, position_max_m  RMS and max over the samples of |e| (3D Euclidean norm) [m]
///   x_rmse_m, x_max_m (y_, z_ too)   RMS and max of |e_x| [m]
///   yaw_rmse_rad                     RMS of wrap(yaw_des - yaw) to (-pi, pi] [rad]
///   attitude_error_rmse, attitude_error_max  RMS and max of Psi [-]
/// A sample counts when t >= after_s, t is a whole multiple of reference_period_s (the controller's
/// period: the recorded reference is the last controller step's, held between steps, so only at a step
/// is it the reference of the sample's own time; 0 counts every sample), and its reference and measured
/// position are finite; the yaw
/// figure uses those of them with a finite yaw and yaw_des, the Psi figures those with a finite Psi.
/// A figure with no sample to count is absent (Psi's for a controller that reports none).
struct TrackingFigures {
  std::size_t samples = 0;  ///< samples counted by the position figures
  std::map<std::string, double> values;
};

/// "position_rmse_m", "position_max_m", "x_rmse_m", "x_max_m", "y_rmse_m", "y_max_m", "z_rmse_m",
/// "z_max_m", "yaw_rmse_rad", "attitude_error_rmse", "attitude_error_max".
const std::vector<std::string>& tracking_figure_names();

/// The figures over the samples with t >= after_s [s] at the multiples of reference_period_s [s] (0: all
/// samples). Throws std::invalid_argument when a column other than an empty attitude_error differs in
/// length from t_s, or when reference_period_s is negative or not finite.
TrackingFigures tracking_figures(const TrackingSeries& series, double after_s, double reference_period_s = 0.0);

}  // namespace quadcosim::analysis
