// A static-pressure barometer in the International Standard Atmosphere's troposphere (ISO 2533, the
// layer up to 11 km geopotential altitude): temperature falls linearly with altitude, and hydrostatic
// balance of an ideal gas gives the pressure
//   T(h) = T0 - L h,   p(h) = p0 (T(h) / T0)^(g0 M / (R L)),
// T0 = 288.15 K, L = 0.0065 K/m, g0 = 9.80665 m/s^2, M = 0.0289644 kg/mol, R = 8.31432 J/(mol K)
// (exponent 5.25588), p0 the pressure at mean sea level (101325 Pa in the standard day). The vehicle's
// altitude h above mean sea level is the site's altitude plus its world z; it is used as geopotential
// altitude (the two differ by h^2 / r_earth: 0.16 m at 1 km).
// The reading is p(h) + bias + n: white noise n ~ N(0, sigma^2), a bias that starts at
// N(0, bias_initial^2) and walks (drift) by N(0, q^2 dt) per sample of period dt. The pressure altitude
// (the ISA inverse of the reading, what an autopilot's barometer driver reports) comes with it.
#pragma once

#include "model/quadrotor.hpp"
#include "model/random.hpp"
#include "sensors/timing.hpp"

namespace quadcosim::sensors {

namespace isa {
inline constexpr double kT0_K = 288.15;       ///< sea-level temperature
inline constexpr double kLapse_K_m = 0.0065;  ///< temperature lapse rate L
inline constexpr double kG0_m_s2 = 9.80665;   ///< standard gravity
inline constexpr double kMolarMass_kg_mol = 0.0289644;
inline constexpr double kGasConstant_J_mol_K = 8.31432;  // R*, the value ISO 2533 and the US Standard Atmosphere use
inline constexpr double kP0_Pa = 101325.0;               ///< standard sea-level pressure
inline constexpr double kTropopause_m = 11000.0;         ///< top of the layer modelled
}  // namespace isa

/// ISA troposphere pressure [Pa] at geopotential altitude h [m] with sea-level pressure p0 [Pa].
double isa_pressure(double altitude_m, double sea_level_Pa = isa::kP0_Pa);
/// Its inverse: the pressure altitude [m] of a pressure [Pa].
double isa_pressure_altitude(double pressure_Pa, double sea_level_Pa = isa::kP0_Pa);
/// ISA troposphere temperature [K] at h [m].
double isa_temperature(double altitude_m);

struct BarometerConfig {
  Timing timing;
  double site_altitude_m = 0.0;                ///< altitude of the world origin above mean sea level [m]
  double sea_level_pressure_Pa = isa::kP0_Pa;  ///< p0 of the day
  double noise_sigma_Pa = 0.0;                 ///< white noise per sample [Pa]
  double drift_Pa_sqrt_s = 0.0;                ///< bias random walk [Pa/sqrt(s)]
  double bias_initial_Pa = 0.0;                ///< turn-on bias standard deviation [Pa]
};

struct BarometerSample {
  double pressure_Pa = 0.0;    ///< the reading [Pa]
  double variance_Pa2 = 0.0;   ///< white-noise variance [Pa^2]
  double altitude_m = 0.0;     ///< pressure altitude of the reading above mean sea level [m] (sea_level_pressure)
  double temperature_K = 0.0;  ///< the ISA temperature at the true altitude [K]
};

class Barometer {
 public:
  Barometer() = default;
  /// `period_s`: the sensor's sample period (the drift's step); `rng`: its own stream.
  Barometer(const BarometerConfig& config, double period_s, model::Rng rng);
  BarometerSample measure(const model::Outputs& truth);
  const BarometerConfig& config() const { return config_; }
  double bias_Pa() const { return bias_Pa_; }

 private:
  BarometerConfig config_;
  double drift_step_Pa_ = 0.0;
  double bias_Pa_ = 0.0;
  model::Rng rng_;
};

}  // namespace quadcosim::sensors
