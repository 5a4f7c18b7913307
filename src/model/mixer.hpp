// The mixing matrix of eq. (4): squared rotor speeds -> collective thrust and body torques.
#pragma once

#include <Eigen/Core>

#include "model/vehicle_params.hpp"

namespace quadcosim::model {

using Vector4 = Eigen::Vector4d;
using Matrix4 = Eigen::Matrix4d;

/// Rotor i's position in the body frame [m] (z = 0), for the layout of `p`.
Eigen::Vector3d rotor_position_B(const VehicleParams& p, int i);

/// M with [U1 U2 U3 U4]^T = M [w1^2 .. w4^2]^T: U1 the collective thrust along +z_B [N], U2..U4 the
/// torques about x_B, y_B, z_B [N m]. Built from the rotor positions (tau = r x F) and spin signs;
/// for the '+' layout this is exactly eq. (4).
Matrix4 mixer_matrix(const VehicleParams& p);

}  // namespace quadcosim::model
