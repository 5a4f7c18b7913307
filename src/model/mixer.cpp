#include "model/mixer.hpp"

#include <cmath>
#include <numbers>

namespace quadcosim::model {

Eigen::Vector3d rotor_position_B(const VehicleParams& p, int i) {
  // Rotors are numbered clockwise seen from above, starting at the nose ('+') or front-left ('x').
  const double offset = p.layout == RotorLayout::kPlus ? 0.0 : std::numbers::pi / 4.0;
  const double angle = offset - i * (std::numbers::pi / 2.0);
  // Exact direction cosines on the axes and diagonals: the '+' matrix gets the structural zeros of
  // eq. (4), and the 'x' rotors equal lever arms (cos and sin of the diagonals differ in the last
  // bit, which would leave a torque at four equal rotor speeds).
  auto snap = [](double v) {
    const double diag = std::sqrt(0.5);
    if (std::abs(v) < 1e-12) return 0.0;
    if (std::abs(std::abs(v) - diag) < 1e-12) return std::copysign(diag, v);
    if (std::abs(std::abs(v) - 1.0) < 1e-12) return std::copysign(1.0, v);
    return v;
  };
  return {p.arm_length_m * snap(std::cos(angle)), p.arm_length_m * snap(std::sin(angle)), 0.0};
}

Matrix4 mixer_matrix(const VehicleParams& p) {
  Matrix4 M;
  for (int i = 0; i < 4; ++i) {
    const Eigen::Vector3d r = rotor_position_B(p, i);
    // Thrust k_t w^2 along +z_B at r gives torque r x (0, 0, F) = (r_y F, -r_x F, 0).
    M(0, i) = p.kt_N_per_rad2_s2;
    M(1, i) = r.y() * p.kt_N_per_rad2_s2;
    M(2, i) = -r.x() * p.kt_N_per_rad2_s2;
    M(3, i) = p.spin[i] * p.km_Nm_per_rad2_s2;
  }
  return M;
}

}  // namespace quadcosim::model
