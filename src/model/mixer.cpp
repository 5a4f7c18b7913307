#include "model/mixer.hpp"

#include <Eigen/LU>
#include <cmath>
#include <numbers>

namespace quadcosim::model {

Eigen::Vector3d rotor_position_B(const VehicleParams& p, int i) {
  if (p.layout == RotorLayout::kCustom) return p.rotor_positions_m[static_cast<std::size_t>(i)];
  // Rotors are numbered clockwise seen from above, starting at the nose ('+' kinds) or half a spacing
  // counter-clockwise of it ('x' kinds: front-left).
  const int n = layout_rotor_count(p.layout);
  const bool plus =
      p.layout == RotorLayout::kPlus || p.layout == RotorLayout::kHexPlus || p.layout == RotorLayout::kOctoPlus;
  const double spacing = 2.0 * std::numbers::pi / n;  // pi/2 exactly for four rotors
  const double offset = plus ? 0.0 : std::numbers::pi / n;
  const double angle = offset - i * spacing;
  // Exact direction cosines on the axes, the diagonals and the 30/60 deg lines: the '+' matrix gets
  // the structural zeros of eq. (4), and the 'x' rotors equal lever arms (cos and sin of the diagonals
  // differ in the last bit, which would leave a torque at four equal rotor speeds).
  auto snap = [](double v) {
    const double diag = std::sqrt(0.5);
    const double c30 = std::sqrt(3.0) / 2.0;
    if (std::abs(v) < 1e-12) return 0.0;
    if (std::abs(std::abs(v) - diag) < 1e-12) return std::copysign(diag, v);
    if (std::abs(std::abs(v) - 1.0) < 1e-12) return std::copysign(1.0, v);
    if (std::abs(std::abs(v) - 0.5) < 1e-12) return std::copysign(0.5, v);
    if (std::abs(std::abs(v) - c30) < 1e-12) return std::copysign(c30, v);
    return v;
  };
  return {p.arm_length_m * snap(std::cos(angle)), p.arm_length_m * snap(std::sin(angle)), 0.0};
}

MixerMatrix mixer_matrix(const VehicleParams& p) {
  MixerMatrix M(4, p.rotor_count);
  for (int i = 0; i < p.rotor_count; ++i) {
    const Eigen::Vector3d r = rotor_position_B(p, i);
    // Thrust k_t w^2 along +z_B at r gives torque r x (0, 0, F) = (r_y F, -r_x F, 0).
    M(0, i) = p.kt_N_per_rad2_s2;
    M(1, i) = r.y() * p.kt_N_per_rad2_s2;
    M(2, i) = -r.x() * p.kt_N_per_rad2_s2;
    M(3, i) = p.spin[static_cast<std::size_t>(i)] * p.km_Nm_per_rad2_s2;
  }
  return M;
}

Matrix4 mixer_matrix4(const VehicleParams& p) {
  Matrix4 M = mixer_matrix(p).leftCols<4>();
  return M;
}

AllocationMatrix allocation_matrix(const VehicleParams& p) {
  if (p.rotor_count == 4) {
    const Matrix4 inverse = mixer_matrix4(p).inverse();
    return inverse;
  }
  const MixerMatrix M = mixer_matrix(p);
  const Matrix4 MMt = M * M.transpose();
  return M.transpose() * MMt.inverse();
}

}  // namespace quadcosim::model
