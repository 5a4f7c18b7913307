#include "sensors/barometer.hpp"

#include <cmath>

namespace quadcosim::sensors {

namespace {
constexpr double kExponent = isa::kG0_m_s2 * isa::kMolarMass_kg_mol / (isa::kGasConstant_J_mol_K * isa::kLapse_K_m);
}  // namespace

double isa_temperature(double altitude_m) { return isa::kT0_K - isa::kLapse_K_m * altitude_m; }

double isa_pressure(double altitude_m, double sea_level_Pa) {
  return sea_level_Pa * std::pow(isa_temperature(altitude_m) / isa::kT0_K, kExponent);
}

double isa_pressure_altitude(double pressure_Pa, double sea_level_Pa) {
  return isa::kT0_K / isa::kLapse_K_m * (1.0 - std::pow(pressure_Pa / sea_level_Pa, 1.0 / kExponent));
}

Barometer::Barometer(const BarometerConfig& config, double period_s, model::Rng rng)
    : config_(config), drift_step_Pa_(config.drift_Pa_sqrt_s * std::sqrt(period_s)), rng_(rng) {
  if (config.bias_initial_Pa > 0.0) bias_Pa_ = config.bias_initial_Pa * rng_.normal();
}

BarometerSample Barometer::measure(const model::Outputs& truth) {
  const double h = config_.site_altitude_m + truth.p_W.z();
  BarometerSample s;
  s.pressure_Pa = isa_pressure(h, config_.sea_level_pressure_Pa) + bias_Pa_;
  if (config_.noise_sigma_Pa > 0.0) s.pressure_Pa += config_.noise_sigma_Pa * rng_.normal();
  if (drift_step_Pa_ > 0.0) bias_Pa_ += drift_step_Pa_ * rng_.normal();
  s.variance_Pa2 = config_.noise_sigma_Pa * config_.noise_sigma_Pa;
  s.altitude_m = isa_pressure_altitude(s.pressure_Pa, config_.sea_level_pressure_Pa);
  s.temperature_K = isa_temperature(h);
  return s;
}

}  // namespace quadcosim::sensors
