// Control allocation (Algorithm 1, lines 16-20): [U1..U4] -> rotor speeds.
#pragma once

#include <Eigen/Core>
#include <array>

namespace quadcosim::control {

struct Allocation {
  Eigen::Vector4d omega_rad_s;      ///< commanded rotor speeds [rad/s]
  std::array<bool, 4> saturated{};  ///< rotor i hit omega_min or omega_max
};

/// Omega^2 = M^-1 U, each entry clamped to [omega_min^2, omega_max^2], omega = sqrt(max(0, .)).
/// `mixer_inverse` is M^-1 of eq. (4).
Allocation allocate(const Eigen::Matrix4d& mixer_inverse, const Eigen::Vector4d& U, double omega_min_rad_s,
                    double omega_max_rad_s);

}  // namespace quadcosim::control
