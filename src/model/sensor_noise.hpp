// Sensor noise: white noise plus a bias random walk on 3-vectors (gyro, accelerometer, position,
// velocity) and a small random rotation on attitudes.
//
// Datasheet units are converted here, at the edge (IEEE Std 952 / 1293 conventions, as in Kalibr's
// and PX4's IMU noise models): a white-noise density N [unit/√Hz] sampled at f [Hz] gives a discrete
// standard deviation σ_d = N √f; a bias random walk density B [unit/s/√Hz = unit/√s] gives per
// sample of period Δt = 1/f a bias increment b_{k+1} = b_k + B √Δt n_k. The bias starts at
// N(0, bias_initial²) per axis (turn-on bias).
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "model/random.hpp"

namespace quadcosim::model {

/// σ_d = density √rate: white-noise density [unit/√Hz] -> discrete sigma at rate_hz [Hz].
inline double discrete_sigma(double density, double rate_hz) { return density * std::sqrt(rate_hz); }
/// Bias increment sigma per sample: random-walk density [unit/√s] √Δt.
inline double bias_step_sigma(double random_walk, double period_s) { return random_walk * std::sqrt(period_s); }

/// Discrete noise on a 3-vector: y = x + b + σ n, then b += σ_b n'.
struct NoiseSpec {
  double white_sigma = 0.0;         ///< per-sample standard deviation [unit]
  double bias_step_sigma = 0.0;     ///< per-sample bias increment standard deviation [unit]
  double bias_initial_sigma = 0.0;  ///< standard deviation of the turn-on bias [unit]
  bool active() const { return white_sigma > 0.0 || bias_step_sigma > 0.0 || bias_initial_sigma > 0.0; }
};

class Vector3Noise {
 public:
  Vector3Noise() = default;
  /// Draws the turn-on bias from `rng` (its own stream).
  Vector3Noise(const NoiseSpec& spec, Rng rng);
  /// One sample: truth + bias + white noise; then the bias walks one step.
  Eigen::Vector3d sample(const Eigen::Vector3d& truth);
  const Eigen::Vector3d& bias() const { return bias_; }

 private:
  NoiseSpec spec_;
  Rng rng_;
  Eigen::Vector3d bias_ = Eigen::Vector3d::Zero();
};

/// q ⊗ exp(δθ / 2) with δθ ~ N(0, σ² I) in the body frame [rad] (σ = 0: q unchanged).
Eigen::Quaterniond perturb_attitude(const Eigen::Quaterniond& q, double sigma_rad, Rng& rng);

}  // namespace quadcosim::model
