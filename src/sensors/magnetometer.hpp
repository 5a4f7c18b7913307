// A three-axis magnetometer: the Earth's field, constant over the flight area, seen in the body frame,
// plus a hard-iron offset (the vehicle's own magnetised parts and currents: a constant vector in the
// body frame) and white noise.
//
// The world field from its three published elements (what a geomagnetic model such as the WMM gives
// for a place and date): total intensity F, inclination I (dip below the horizontal, positive down)
// and declination D (east of true north). In the world frame of quadcosim (ENU: x east, y north, z up):
//   B_W = F (cos I sin D, cos I cos D, -sin I)
// and the body reading B_B = R_WB^T B_W + b_hard + n, n ~ N(0, sigma^2 I) per axis. Soft iron (a
// scale and skew matrix) is not modelled.
#pragma once

#include <Eigen/Core>

#include "model/quadrotor.hpp"
#include "model/random.hpp"
#include "sensors/timing.hpp"

namespace quadcosim::sensors {

struct MagnetometerConfig {
  Timing timing;
  double field_T = 50e-6;                                 ///< total intensity F [T]
  double inclination_rad = 1.0471975511965976;            ///< I, 60 deg [rad], positive: the field points down
  double declination_rad = 0.0;                           ///< D, east of true north [rad]
  double noise_sigma_T = 0.0;                             ///< white noise per axis and sample [T]
  Eigen::Vector3d hard_iron_T = Eigen::Vector3d::Zero();  ///< constant offset in the body frame [T]
};

/// The world field B_W [T] of intensity, inclination and declination (ENU).
Eigen::Vector3d earth_field_W(double field_T, double inclination_rad, double declination_rad);

/// What the magnetometer publishes.
struct MagnetometerSample {
  Eigen::Vector3d field_B_T = Eigen::Vector3d::Zero();  ///< the measured field in the body frame [T]
  double variance_T2 = 0.0;                             ///< per-axis white-noise variance [T^2]
};

class Magnetometer {
 public:
  Magnetometer() = default;
  /// `rng`: the sensor's own stream (model::stream_seed(seed, vehicle, "magnetometer")).
  Magnetometer(const MagnetometerConfig& config, model::Rng rng);
  MagnetometerSample measure(const model::Outputs& truth);
  const MagnetometerConfig& config() const { return config_; }

 private:
  MagnetometerConfig config_;
  Eigen::Vector3d field_W_ = Eigen::Vector3d::Zero();
  model::Rng rng_;
};

}  // namespace quadcosim::sensors
