#include "control/attitude_lqr.hpp"

#include "control/care.hpp"
#include "control/eigenvalues.hpp"

namespace quadcosim::control {

AxisLqr design_axis_lqr(double inertia_kg_m2, const LqrWeights& w) {
  if (!(inertia_kg_m2 > 0.0)) throw CareError("LQR: inertia must be > 0");
  AxisLqr d;
  d.A << 0.0, -1.0, 0.0, 0.0;  // de/dt = -rate (constant setpoint)
  d.B << 0.0, 1.0 / inertia_kg_m2;
  d.Q << w.q_angle, 0.0, 0.0, w.q_rate;
  d.R = w.r;
  const Eigen::MatrixXd K = lqr_gain(d.A, d.B, d.Q, Eigen::MatrixXd::Constant(1, 1, w.r));
  d.K = K;
  d.closed_loop_poles = eigenvalues(d.A - d.B * d.K);
  return d;
}

}  // namespace quadcosim::control
