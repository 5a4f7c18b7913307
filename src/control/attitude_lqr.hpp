// Per-axis attitude LQR on the paper's error state (eqs. (14)-(16)).
#pragma once

#include <Eigen/Core>
#include <complex>

namespace quadcosim::control {

/// Weights of the cost (16): J = integral of q_angle e^2 + q_rate rate^2 + r U^2.
struct LqrWeights {
  double q_angle = 1.0;  ///< weight on the angle error e [1/rad^2]
  double q_rate = 1.0;   ///< weight on the body rate [s^2/rad^2]
  double r = 1.0;        ///< weight on the torque [1/(N m)^2]
};

/// One axis's design: x = [e, rate], e = angle_des - angle, dx = A x + B U (eq. (14)),
/// U = -K x (eq. (15)) with K from the CARE. In Algorithm 1's notation k1 = -K(0), k2 = K(1).
struct AxisLqr {
  Eigen::Matrix2d A;
  Eigen::Vector2d B;
  Eigen::Matrix2d Q;
  double R = 1.0;
  Eigen::RowVector2d K;
  Eigen::Vector2cd closed_loop_poles;  ///< eigenvalues of A - B K [1/s]

  /// Torque [N m] for angle error e [rad] and body rate [rad/s].
  double torque(double angle_error_rad, double rate_rad_s) const {
    return -(K(0) * angle_error_rad + K(1) * rate_rad_s);
  }
};

/// Designs the axis controller for inertia I [kg m^2]. Throws CareError for weights that admit no
/// stabilising solution (e.g. r <= 0, negative q).
AxisLqr design_axis_lqr(double inertia_kg_m2, const LqrWeights& weights);

}  // namespace quadcosim::control
