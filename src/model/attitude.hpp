// Attitude conventions: unit quaternion q_WB rotates body (FLU) vectors into the world (ENU) frame;
// Euler angles are Z-Y-X (yaw psi about z_W, then pitch theta about the new y, then roll phi about
// the new x), so R_WB = Rz(psi) Ry(theta) Rx(phi), the transpose of the paper's eq. (3).
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "model/angle.hpp"  // wrap_pi

namespace quadcosim::model {

/// Euler angles [rad], Z-Y-X convention.
struct Euler {
  double roll_rad = 0.0;   ///< phi, in [-pi, pi]
  double pitch_rad = 0.0;  ///< theta, in [-pi/2, pi/2]
  double yaw_rad = 0.0;    ///< psi, in [-pi, pi]
};

/// q_WB for the given Z-Y-X angles (unit norm, w >= 0 not enforced).
Eigen::Quaterniond quaternion_from_euler(const Euler& e);

/// Z-Y-X angles of a unit quaternion. At pitch = +-pi/2 (gimbal lock) roll is reported as 0 and the
/// whole heading goes to yaw. The input is normalised first; a zero quaternion gives all zeros.
Euler euler_from_quaternion(const Eigen::Quaterniond& q_WB);

}  // namespace quadcosim::model
