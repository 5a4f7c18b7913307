#include "sitl/frames.hpp"

namespace quadcosim::sitl {

namespace {

// R_NED_ENU: rows are the NED axes written in ENU.
Eigen::Matrix3d ned_from_enu() {
  Eigen::Matrix3d r;
  r << 0, 1, 0,  //
      1, 0, 0,   //
      0, 0, -1;
  return r;
}

// R_FLU_FRD = diag(1, -1, -1).
Eigen::Matrix3d flu_from_frd() { return Eigen::Vector3d(1, -1, -1).asDiagonal(); }

}  // namespace

Eigen::Vector3d enu_to_ned(const Eigen::Vector3d& v_enu) { return {v_enu.y(), v_enu.x(), -v_enu.z()}; }
Eigen::Vector3d ned_to_enu(const Eigen::Vector3d& v_ned) { return {v_ned.y(), v_ned.x(), -v_ned.z()}; }
Eigen::Vector3d flu_to_frd(const Eigen::Vector3d& v_flu) { return {v_flu.x(), -v_flu.y(), -v_flu.z()}; }
Eigen::Vector3d frd_to_flu(const Eigen::Vector3d& v_frd) { return {v_frd.x(), -v_frd.y(), -v_frd.z()}; }

Eigen::Quaterniond attitude_ned_frd(const Eigen::Quaterniond& q_WB) {
  const Eigen::Matrix3d r = ned_from_enu() * q_WB.normalized().toRotationMatrix() * flu_from_frd();
  Eigen::Quaterniond q(r);
  q.normalize();
  if (q.w() < 0) q.coeffs() = -q.coeffs();  // one sign for one attitude: w >= 0
  return q;
}

}  // namespace quadcosim::sitl
