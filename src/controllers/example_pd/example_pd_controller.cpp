#include "controllers/example_pd/example_pd_controller.hpp"

#include <Eigen/LU>
#include <algorithm>
#include <array>
#include <cmath>

#include "control/allocation.hpp"
#include "model/attitude.hpp"
#include "model/mixer.hpp"

namespace quadcosim::controllers {

namespace {
using Table = control::ParameterTable<ExamplePdParams>;
const std::array<std::string, 1> kOutputs = {"thrust_N"};
}  // namespace

ExamplePdController::ExamplePdController(const model::VehicleParams& vehicle)
    : ControllerWith(ExamplePdParams{}), vehicle_(vehicle), allocation_(vehicle) {}

const Table& ExamplePdController::table() const {
  static const Table table({
      Table::number(
          "position.kp", "1/s^2", 0, 1e3, "acceleration per metre of position error",
          [](auto& p) -> auto& { return p.position_kp; }),
      Table::number(
          "position.kd", "1/s", 0, 1e3, "acceleration per m/s of velocity error",
          [](auto& p) -> auto& { return p.position_kd; }),
      Table::number(
          "attitude.kp", "1/s^2", 0, 1e5, "angular acceleration per radian of attitude error",
          [](auto& p) -> auto& { return p.attitude_kp; }),
      Table::number(
          "attitude.kd", "1/s", 0, 1e4, "angular acceleration per rad/s of body rate",
          [](auto& p) -> auto& { return p.attitude_kd; }),
      Table::number(
          "max_tilt", "rad", 0.01, 1.2, "bound on the commanded roll and pitch",
          [](auto& p) -> auto& { return p.max_tilt; }),
  });
  return table;
}

std::span<const std::string> ExamplePdController::output_names() const { return kOutputs; }

void ExamplePdController::step(const control::Observation& o, const control::Reference& r, double,
                               control::ControllerOutput& out) {
  const ExamplePdParams& k = params();
  const double g = vehicle_.gravity_m_s2;
  // Desired acceleration in the world frame (only z in attitude mode).
  Eigen::Vector3d a = k.position_kp * (r.p_W - o.p_W) + k.position_kd * (r.v_W - o.v_W) + r.a_W;
  double roll_des = r.roll_rad, pitch_des = r.pitch_rad;
  out.tilt_saturated = false;
  if (r.mode == control::Mode::kPosition) {
    // Small-angle inversion of the thrust direction at the current heading, then the tilt bound.
    const double c = std::cos(o.yaw_rad), s = std::sin(o.yaw_rad);
    pitch_des = (a.x() * c + a.y() * s) / g;
    roll_des = (a.x() * s - a.y() * c) / g;
    out.tilt_saturated = std::abs(roll_des) > k.max_tilt || std::abs(pitch_des) > k.max_tilt;
    roll_des = std::clamp(roll_des, -k.max_tilt, k.max_tilt);
    pitch_des = std::clamp(pitch_des, -k.max_tilt, k.max_tilt);
  }
  const double tilt = std::max(std::cos(o.roll_rad) * std::cos(o.pitch_rad), 0.5);
  out.U[0] = vehicle_.mass_kg * (g + a.z()) / tilt;
  const Eigen::Vector3d e(roll_des - o.roll_rad, pitch_des - o.pitch_rad, model::wrap_pi(r.yaw_rad - o.yaw_rad));
  const Eigen::Vector3d J(vehicle_.Ixx_kg_m2, vehicle_.Iyy_kg_m2, vehicle_.Izz_kg_m2);
  out.U.tail<3>() = J.cwiseProduct(k.attitude_kp * e - k.attitude_kd * o.w_B);

  const control::Allocation alloc =
      allocation_.allocate(out.U, vehicle_.motor.omega_min_rad_s, vehicle_.motor.omega_max_rad_s);
  model::assign_rotors(out.omega_rad_s, alloc.omega_rad_s);
  out.rotor_saturated = alloc.saturated;
  out.roll_des_rad = roll_des;
  out.pitch_des_rad = pitch_des;
  out.yaw_des_rad = r.yaw_rad;
  out.attitude_error = control::attitude_error(model::quaternion_from_euler({roll_des, pitch_des, r.yaw_rad}), o.q_WB);
  out.outputs[0] = out.U[0];
}

}  // namespace quadcosim::controllers
