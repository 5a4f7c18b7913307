#include "sitl/motor_map.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <stdexcept>

namespace quadcosim::sitl {

Eigen::Vector4d MotorMap::omega_from_pwm(std::span<const std::uint16_t> pwm_us) const {
  Eigen::Vector4d w;
  for (int i = 0; i < 4; ++i) {
    const auto ch = static_cast<std::size_t>(channel_of_rotor[i]);
    const double pwm = ch < pwm_us.size() ? pwm_us[ch] : 0.0;
    const double f = std::clamp((pwm - pwm_min_us) / (pwm_max_us - pwm_min_us), 0.0, 1.0);
    w[i] = pwm == 0.0 ? 0.0 : f * omega_max_rad_s;
  }
  return w;
}

double MotorMap::pwm_from_omega(double omega_rad_s) const {
  const double f = std::clamp(omega_rad_s / omega_max_rad_s, 0.0, 1.0);
  return pwm_min_us + f * (pwm_max_us - pwm_min_us);
}

MotorMap motor_map_for(const model::VehicleParams& vehicle, double pwm_min_us, double pwm_max_us) {
  if (vehicle.rotor_count != 4 ||
      (vehicle.layout != model::RotorLayout::kPlus && vehicle.layout != model::RotorLayout::kX)) {
    throw std::invalid_argument(fmt::format(
        "vehicle layout {} with {} rotors: the SITL bridges fly quadrotor frames only (ArduPilot FRAME_CLASS 1, "
        "PX4's quad airframes; layout plus or x)",
        model::to_string(vehicle.layout), vehicle.rotor_count));
  }
  if (vehicle.spin[0] != 1 || vehicle.spin[1] != -1 || vehicle.spin[2] != 1 || vehicle.spin[3] != -1) {
    throw std::invalid_argument(fmt::format(
        "vehicle spin signs [{}, {}, {}, {}]: an ArduPilot quad (FRAME_TYPE 0 plus, 1 x) needs [1, -1, 1, -1] "
        "(rotors 1 and 3 clockwise seen from above)",
        vehicle.spin[0], vehicle.spin[1], vehicle.spin[2], vehicle.spin[3]));
  }
  if (!(pwm_max_us > pwm_min_us)) {
    throw std::invalid_argument(fmt::format("PWM range [{:g}, {:g}] us is empty", pwm_min_us, pwm_max_us));
  }
  MotorMap m;
  m.pwm_min_us = pwm_min_us;
  m.pwm_max_us = pwm_max_us;
  m.omega_max_rad_s = vehicle.motor.omega_max_rad_s;
  m.frame_type = vehicle.layout == model::RotorLayout::kPlus ? 0 : 1;
  return m;
}

}  // namespace quadcosim::sitl
