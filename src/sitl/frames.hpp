// quadcosim's frames (world ENU, body FLU: docs/architecture.md) and ArduPilot's (earth NED relative to
// home, body FRD), converted here and nowhere else. Both changes are proper rotations by pi about an
// axis: ENU -> NED swaps x and y and negates z; FLU -> FRD negates y and z.
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>

namespace quadcosim::sitl {

/// A world vector [any unit] from ENU (east, north, up) to NED (north, east, down).
Eigen::Vector3d enu_to_ned(const Eigen::Vector3d& v_enu);
/// A world vector from NED to ENU (the same map: it is its own inverse).
Eigen::Vector3d ned_to_enu(const Eigen::Vector3d& v_ned);
/// A body vector [any unit] from FLU (forward, left, up) to FRD (forward, right, down).
Eigen::Vector3d flu_to_frd(const Eigen::Vector3d& v_flu);
/// A body vector from FRD to FLU (the same map).
Eigen::Vector3d frd_to_flu(const Eigen::Vector3d& v_frd);
/// The attitude body FRD -> earth NED of a vehicle whose attitude is `q_WB` (body FLU -> world ENU):
/// R_NED_FRD = R_NED_ENU R_ENU_FLU R_FLU_FRD. Normalised.
Eigen::Quaterniond attitude_ned_frd(const Eigen::Quaterniond& q_WB);

}  // namespace quadcosim::sitl
