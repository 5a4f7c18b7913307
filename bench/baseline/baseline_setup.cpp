#include "baseline/baseline_setup.hpp"

#include <Eigen/LU>

#include "model/mixer.hpp"

namespace quadcosim::baseline {

BaselineLoop make_baseline(const model::VehicleParams& veh, const controllers::PaperParams& p, double z_des_m) {
  BaselineVehicle v{};
  v.mass_kg = veh.mass_kg;
  v.gravity_m_s2 = veh.gravity_m_s2;
  v.inertia_kg_m2[0] = veh.Ixx_kg_m2;
  v.inertia_kg_m2[1] = veh.Iyy_kg_m2;
  v.inertia_kg_m2[2] = veh.Izz_kg_m2;
  const Eigen::Matrix4d M = model::mixer_matrix(veh);
  const Eigen::Matrix4d Mi = M.inverse();
  for (int r = 0; r < 4; ++r) {
    for (int c = 0; c < 4; ++c) {
      v.mixer[r][c] = M(r, c);
      v.mixer_inverse[r][c] = Mi(r, c);
    }
  }
  v.omega_max_rad_s = veh.motor.omega_max_rad_s;
  BaselineGains g{};
  const control::LqrWeights w[3] = {p.roll, p.pitch, p.yaw};
  const double I[3] = {veh.Ixx_kg_m2, veh.Iyy_kg_m2, veh.Izz_kg_m2};
  for (int a = 0; a < 3; ++a) {
    const control::AxisLqr axis = control::design_axis_lqr(I[a], w[a]);
    g.k_angle[a] = -axis.K(0);
    g.k_rate[a] = axis.K(1);
  }
  g.kp_z = p.altitude.kp;
  g.kd_z = p.altitude.kd;
  g.min_cos_tilt = p.altitude.min_cos_tilt;
  return BaselineLoop(v, g, z_des_m);
}

}  // namespace quadcosim::baseline
