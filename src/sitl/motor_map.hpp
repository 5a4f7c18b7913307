// Which servo channel of ArduPilot drives which quadcosim rotor, and what a PWM width means as a rotor
// speed.
//
// ArduPilot's quad matrix (FRAME_CLASS 1), output channels 1..4 (angles clockwise from the nose):
//   FRAME_TYPE 0 (plus): 1 right (90 deg) CCW, 2 left (-90) CCW, 3 front (0) CW, 4 back (180) CW
//   FRAME_TYPE 1 (x):    1 front-right CCW, 2 back-left CCW, 3 front-left CW, 4 back-right CW
// quadcosim numbers its rotors clockwise from the nose ('+': 1 front, 2 right, 3 back, 4 left) or from
// the front-left ('x'), and with spin signs (+1, -1, +1, -1) rotors 1 and 3 turn clockwise seen from
// above (model/vehicle_params.hpp). Both layouts then take the same channels: rotor 1 <- channel 3,
// rotor 2 <- 1, rotor 3 <- 4, rotor 4 <- 2, every rotor turning the way ArduPilot expects.
//
// PWM to speed: an ESC whose speed is proportional to its throttle, omega = omega_max * f with
// f = (pwm - pwm_min) / (pwm_max - pwm_min) clamped to [0, 1], so thrust k_t omega^2 grows as f^2
// (ArduPilot's MOT_THST_EXPO = 1 is then the exact linearisation). A channel at 0 (no output) is 0.
#pragma once

#include <Eigen/Core>
#include <array>
#include <cstdint>
#include <span>
#include <string>

#include "model/vehicle_params.hpp"

namespace quadcosim::sitl {

struct MotorMap {
  /// channel_of_rotor[i]: the 0-based servo channel that drives quadcosim rotor i.
  std::array<int, 4> channel_of_rotor = {2, 0, 3, 1};
  double pwm_min_us = 1000.0;  ///< MOT_PWM_MIN: zero speed at and below
  double pwm_max_us = 2000.0;  ///< MOT_PWM_MAX: omega_max at and above
  double omega_max_rad_s = 12000.0;
  int frame_type = 0;  ///< ArduPilot's FRAME_TYPE for the layout (0 plus, 1 x)

  /// Rotor speeds [rad/s] from a servo packet's channels (at least 4).
  Eigen::Vector4d omega_from_pwm(std::span<const std::uint16_t> pwm_us) const;
  /// The PWM width [us] for one rotor speed (the inverse, for the test firmware and checks).
  double pwm_from_omega(double omega_rad_s) const;
};

/// The map for `vehicle`: its layout's FRAME_TYPE, its omega_max. Throws std::invalid_argument naming
/// the vehicle's spin signs when they are not (+1, -1, +1, -1) (no ArduPilot quad frame turns so).
MotorMap motor_map_for(const model::VehicleParams& vehicle, double pwm_min_us = 1000.0, double pwm_max_us = 2000.0);

}  // namespace quadcosim::sitl
