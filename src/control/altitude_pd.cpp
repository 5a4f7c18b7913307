#include "control/altitude_pd.hpp"

#include <algorithm>
#include <cmath>

namespace quadcosim::control {

double collective_thrust(const AltitudeGains& g, double mass_kg, double gravity_m_s2, double z_des_m, double z_m,
                         double vz_m_s, double roll_rad, double pitch_rad) {
  const double u = mass_kg * gravity_m_s2 + g.kp * (z_des_m - z_m) - g.kd * vz_m_s;
  const double tilt = std::max(std::cos(roll_rad) * std::cos(pitch_rad), g.min_cos_tilt);
  return std::max(0.0, u / tilt);
}

}  // namespace quadcosim::control
