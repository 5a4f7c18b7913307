#include "model/sensor_noise.hpp"

namespace quadcosim::model {

Vector3Noise::Vector3Noise(const NoiseSpec& spec, Rng rng) : spec_(spec), rng_(rng) {
  if (spec_.bias_initial_sigma > 0.0) {
    for (int i = 0; i < 3; ++i) bias_[i] = spec_.bias_initial_sigma * rng_.normal();
  }
}

Eigen::Vector3d Vector3Noise::sample(const Eigen::Vector3d& truth) {
  Eigen::Vector3d y = truth + bias_;
  if (spec_.white_sigma > 0.0) {
    for (int i = 0; i < 3; ++i) y[i] += spec_.white_sigma * rng_.normal();
  }
  if (spec_.bias_step_sigma > 0.0) {
    for (int i = 0; i < 3; ++i) bias_[i] += spec_.bias_step_sigma * rng_.normal();
  }
  return y;
}

Eigen::Quaterniond perturb_attitude(const Eigen::Quaterniond& q, double sigma_rad, Rng& rng) {
  if (sigma_rad <= 0.0) return q;
  // Drawn z, y, x, one statement each: the order of a function's arguments is the compiler's choice,
  // and this is the order GCC took when the three draws were the constructor's arguments.
  const double dz = sigma_rad * rng.normal();
  const double dy = sigma_rad * rng.normal();
  const double dx = sigma_rad * rng.normal();
  const Eigen::Vector3d d(dx, dy, dz);
  const double angle = d.norm();
  if (angle == 0.0) return q;
  return (q * Eigen::Quaterniond(Eigen::AngleAxisd(angle, d / angle))).normalized();
}

}  // namespace quadcosim::model
