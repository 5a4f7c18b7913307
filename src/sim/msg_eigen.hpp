// Eigen's vectors and quaternions as the messages' Vector3 and Quaternion (sim/messages.hpp).
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "sim/messages.hpp"

namespace quadcosim::sim {

inline msg::Vector3 to_msg(const Eigen::Vector3d& v) { return {v.x(), v.y(), v.z()}; }
inline msg::Quaternion to_msg(const Eigen::Quaterniond& q) { return {q.x(), q.y(), q.z(), q.w()}; }

}  // namespace quadcosim::sim
