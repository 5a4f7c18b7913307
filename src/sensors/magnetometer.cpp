#include "sensors/magnetometer.hpp"

#include <cmath>

namespace quadcosim::sensors {

Eigen::Vector3d earth_field_W(double field_T, double inclination_rad, double declination_rad) {
  const double horizontal = field_T * std::cos(inclination_rad);
  return {horizontal * std::sin(declination_rad), horizontal * std::cos(declination_rad),
          -field_T * std::sin(inclination_rad)};
}

Magnetometer::Magnetometer(const MagnetometerConfig& config, model::Rng rng)
    : config_(config),
      field_W_(earth_field_W(config.field_T, config.inclination_rad, config.declination_rad)),
      rng_(rng) {}

MagnetometerSample Magnetometer::measure(const model::Outputs& truth) {
  MagnetometerSample s;
  s.field_B_T = truth.q_WB.conjugate() * field_W_ + config_.hard_iron_T;
  if (config_.noise_sigma_T > 0.0) {
    for (int i = 0; i < 3; ++i) s.field_B_T[i] += config_.noise_sigma_T * rng_.normal();
  }
  s.variance_T2 = config_.noise_sigma_T * config_.noise_sigma_T;
  return s;
}

}  // namespace quadcosim::sensors
