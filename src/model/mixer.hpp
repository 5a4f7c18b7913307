// The mixing matrix of eq. (4), for any rotor count: squared rotor speeds -> collective thrust and
// body torques.
#pragma once

#include <Eigen/Core>

#include "model/rotor_vector.hpp"
#include "model/vehicle_params.hpp"

namespace quadcosim::model {

using Vector4 = Eigen::Vector4d;
using Matrix4 = Eigen::Matrix4d;

/// Rotor i's position in the body frame [m], for the layout of `p`: the standard layouts on the circle
/// of radius arm_length_m (z = 0), numbered clockwise seen from above (docs/model.md, "Rotor layouts");
/// kCustom's rotor_positions_m[i].
Eigen::Vector3d rotor_position_B(const VehicleParams& p, int i);

/// M (4 x N) with [U1 U2 U3 U4]^T = M [w1^2 .. wN^2]^T: U1 the collective thrust along +z_B [N], U2..U4
/// the torques about x_B, y_B, z_B [N m]. Column i: k_t, then r_i x (0, 0, k_t) = (r_y k_t, -r_x k_t),
/// then spin_i k_m. For the '+' layout this is exactly eq. (4).
MixerMatrix mixer_matrix(const VehicleParams& p);

/// The mixer of a four-rotor vehicle as the fixed-size matrix of eq. (4) (p.rotor_count must be 4).
Matrix4 mixer_matrix4(const VehicleParams& p);

/// The allocation matrix: M^-1 for four rotors (Eigen's closed-form 4x4 inverse, the paper's
/// arithmetic), the Moore-Penrose pseudo-inverse M^+ = M^T (M M^T)^-1 for more (the minimum-norm
/// squared speeds that make a wrench). N x 4.
AllocationMatrix allocation_matrix(const VehicleParams& p);

}  // namespace quadcosim::model
