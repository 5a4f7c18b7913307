// Altitude channel: PD with gravity feedforward and tilt compensation (eqs. (12)-(13)).
#pragma once

namespace quadcosim::control {

struct AltitudeGains {
  double kp = 4.0;  ///< K_p,z [N/m]
  double kd = 2.7;  ///< K_d,z [N s/m]
  /// Floor on cos(phi) cos(theta) in eq. (13) [-]: below it the tilt compensation stops growing, so
  /// the thrust stays bounded when the vehicle is near 90 deg of tilt (or upside down).
  double min_cos_tilt = 0.5;
};

/// Eq. (13): U1 = (m g + K_p (z_des - z) - K_d dz) / max(cos(phi) cos(theta), min_cos_tilt) [N],
/// never negative.
double collective_thrust(const AltitudeGains& gains, double mass_kg, double gravity_m_s2, double z_des_m, double z_m,
                         double vz_m_s, double roll_rad, double pitch_rad);

}  // namespace quadcosim::control
