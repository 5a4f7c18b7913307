#include "controllers/se3/geometric_controller.hpp"

#include <Eigen/LU>
#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <stdexcept>

#include "control/allocation.hpp"
#include "model/attitude.hpp"
#include "model/mixer.hpp"

namespace quadcosim::controllers {

namespace {
constexpr double kBig = 1e9;
constexpr double kPi = 3.14159265358979323846;
using Table = control::ParameterTable<GeometricParams>;

Table make_table() {
  return Table({
      Table::number(
          "k_x.x", "N/m", 0, kBig, "position gain along world x", [](auto& p) -> auto& { return p.k_x[0]; }),
      Table::number(
          "k_x.y", "N/m", 0, kBig, "position gain along world y", [](auto& p) -> auto& { return p.k_x[1]; }),
      Table::number(
          "k_x.z", "N/m", 0, kBig, "position gain along world z (also the attitude mode's altitude loop)",
          [](auto& p) -> auto& { return p.k_x[2]; }),
      Table::number(
          "k_v.x", "N s/m", 0, kBig, "velocity gain along world x", [](auto& p) -> auto& { return p.k_v[0]; }),
      Table::number(
          "k_v.y", "N s/m", 0, kBig, "velocity gain along world y", [](auto& p) -> auto& { return p.k_v[1]; }),
      Table::number(
          "k_v.z", "N s/m", 0, kBig, "velocity gain along world z (also the attitude mode's altitude loop)",
          [](auto& p) -> auto& { return p.k_v[2]; }),
      Table::number(
          "k_R.x", "N m/rad", 0, kBig, "attitude gain about body x (roll)", [](auto& p) -> auto& { return p.k_R[0]; }),
      Table::number(
          "k_R.y", "N m/rad", 0, kBig, "attitude gain about body y (pitch)", [](auto& p) -> auto& { return p.k_R[1]; }),
      Table::number(
          "k_R.z", "N m/rad", 0, kBig, "attitude gain about body z (yaw)", [](auto& p) -> auto& { return p.k_R[2]; }),
      Table::number(
          "k_Omega.x", "N m s/rad", 0, kBig, "body rate gain about x", [](auto& p) -> auto& { return p.k_Omega[0]; }),
      Table::number(
          "k_Omega.y", "N m s/rad", 0, kBig, "body rate gain about y", [](auto& p) -> auto& { return p.k_Omega[1]; }),
      Table::number(
          "k_Omega.z", "N m s/rad", 0, kBig, "body rate gain about z", [](auto& p) -> auto& { return p.k_Omega[2]; }),
      Table::number(
          "max_tilt", "rad", 0.01, kPi, "position mode: largest angle of b3d from vertical (pi: no limit)",
          [](auto& p) -> auto& { return p.max_tilt_rad; }),
      Table::number(
          "min_cos_tilt", "", 0.05, 1, "attitude mode: floor on (R e3)_z in the thrust's tilt compensation",
          [](auto& p) -> auto& { return p.min_cos_tilt; }),
  });
}

const std::array<std::string, 14> kOutputNames = {"e_x.x",     "e_x.y",     "e_x.z",  "e_v.x",         "e_v.y",
                                                  "e_v.z",     "e_R.x",     "e_R.y",  "e_R.z",         "e_Omega.x",
                                                  "e_Omega.y", "e_Omega.z", "thrust", "yaw_torque_cut"};

Eigen::Vector3d vee(const Eigen::Matrix3d& m) { return {m(2, 1), m(0, 2), m(1, 0)}; }

/// The largest |M_z| (with M_z's sign kept) that leaves every rotor's squared speed inside
/// [omega_min^2, omega_max^2] or, for a rotor that (f, M_x, M_y) alone already puts outside, no further
/// out: the yaw torque gives way first, since the drag torque gives little of it and asking for more
/// than the rotors can give would distort the thrust and the roll/pitch torques through the clamp.
/// `Alloc` and `Vec`: Eigen::Matrix4d and Eigen::Vector4d for four rotors (the products as before other
/// rotor counts), the N x 4 allocation and a rotor vector otherwise.
template <class Alloc, class Vec>
double limit_yaw_torque(const Alloc& allocation, const Eigen::Vector4d& U, double omega_min_rad_s,
                        double omega_max_rad_s) {
  Eigen::Vector4d without_yaw = U;
  without_yaw[3] = 0.0;
  const Vec base = allocation * without_yaw;
  const Vec per_Nm = allocation.col(3);
  double lo_Mz = -std::numeric_limits<double>::infinity(), hi_Mz = std::numeric_limits<double>::infinity();
  for (Eigen::Index i = 0; i < base.size(); ++i) {
    if (per_Nm[i] == 0.0) continue;
    const double lo = std::min(omega_min_rad_s * omega_min_rad_s, base[i]);
    const double hi = std::max(omega_max_rad_s * omega_max_rad_s, base[i]);
    double a = (lo - base[i]) / per_Nm[i], b = (hi - base[i]) / per_Nm[i];
    if (a > b) std::swap(a, b);
    lo_Mz = std::max(lo_Mz, a);
    hi_Mz = std::min(hi_Mz, b);
  }
  return std::clamp(U[3], std::min(lo_Mz, 0.0), std::max(hi_Mz, 0.0));
}

/// R_d = [b1d b2d b3d] with b2d = b3d x b1c / |b3d x b1c|, b1c = (cos yaw, sin yaw, 0). When b3d is
/// (nearly) along b1c the heading is undefined; then b1c is the body's current x axis, or world x, and
/// `heading_from_yaw` is false.
Eigen::Matrix3d desired_attitude(const Eigen::Vector3d& b3d, double yaw_rad, const Eigen::Matrix3d& R,
                                 Eigen::Vector3d& b1c, bool& heading_from_yaw) {
  b1c = Eigen::Vector3d(std::cos(yaw_rad), std::sin(yaw_rad), 0.0);
  Eigen::Vector3d n = b3d.cross(b1c);
  heading_from_yaw = n.norm() >= 1e-6;
  if (!heading_from_yaw) {
    b1c = R.col(0);
    n = b3d.cross(b1c);
    if (n.norm() < 1e-6) {
      b1c = Eigen::Vector3d::UnitX();
      n = b3d.cross(b1c);
    }
  }
  Eigen::Matrix3d R_d;
  R_d.col(2) = b3d;
  R_d.col(1) = n.normalized();
  R_d.col(0) = R_d.col(1).cross(b3d);
  return R_d;
}
}  // namespace

Eigen::Vector3d attitude_error_vector(const Eigen::Matrix3d& R_d, const Eigen::Matrix3d& R) {
  return 0.5 * vee(R_d.transpose() * R - R.transpose() * R_d);
}

GeometricParams GeometricParams::for_vehicle(const model::VehicleParams& v) {
  const model::VehicleParams table1;
  GeometricParams p;
  const double mass_ratio = v.mass_kg / table1.mass_kg;
  const Eigen::Vector3d inertia_ratio(v.Ixx_kg_m2 / table1.Ixx_kg_m2, v.Iyy_kg_m2 / table1.Iyy_kg_m2,
                                      v.Izz_kg_m2 / table1.Izz_kg_m2);
  p.k_x *= mass_ratio;
  p.k_v *= mass_ratio;
  p.k_R = p.k_R.cwiseProduct(inertia_ratio);
  p.k_Omega = p.k_Omega.cwiseProduct(inertia_ratio);
  return p;
}

GeometricController::GeometricController(const model::VehicleParams& vehicle)
    : GeometricController(vehicle, GeometricParams::for_vehicle(vehicle)) {}

GeometricController::GeometricController(const model::VehicleParams& vehicle, const GeometricParams& params)
    : ControllerWith(params), vehicle_(vehicle) {
  J_ = vehicle.inertia_tensor();
  if (vehicle_.rotor_count == 4) {
    Eigen::FullPivLU<Eigen::Matrix4d> lu(model::mixer_matrix4(vehicle_));
    if (!lu.isInvertible()) throw std::invalid_argument("the vehicle's mixer matrix is singular");
    mixer_inverse_ = lu.inverse();
    allocation_ = control::RotorAllocation(mixer_inverse_);
  } else {
    if (std::string err = model::validate_rotors(vehicle_); !err.empty()) throw std::invalid_argument(err);
    allocation_ = control::RotorAllocation(vehicle_);  // the pseudo-inverse M^+
  }
}

const control::ParameterTable<GeometricParams>& GeometricController::table() const {
  static const Table table = make_table();
  return table;
}

std::span<const std::string> GeometricController::output_names() const { return kOutputNames; }

void GeometricController::step(const control::Observation& obs, const control::Reference& ref, double /*dt_s*/,
                               control::ControllerOutput& c) {
  const auto& v = vehicle_;
  const GeometricParams& k = params();
  const double m = v.mass_kg, g = v.gravity_m_s2;
  const Eigen::Vector3d e3 = Eigen::Vector3d::UnitZ();
  const Eigen::Matrix3d R = obs.q_WB.normalized().toRotationMatrix();
  const Eigen::Vector3d& Omega = obs.w_B;
  GeometricTerms t;
  t.e_x_W = obs.p_W - ref.p_W;
  t.e_v_W = obs.v_W - ref.v_W;
  c.tilt_saturated = false;
  double f = 0.0;

  if (ref.mode == control::Mode::kPosition) {
    Eigen::Vector3d F = -k.k_x.cwiseProduct(t.e_x_W) - k.k_v.cwiseProduct(t.e_v_W) + m * g * e3 + m * ref.a_W;
    // Tilt limit: beyond max_tilt the horizontal part is cut so that b3d is at max_tilt, keeping the
    // vertical part when it points up (the altitude loop keeps its force).
    const double horizontal = F.head<2>().norm();
    if (std::atan2(horizontal, F.z()) > k.max_tilt_rad) {
      // Straight down (no horizontal part): nothing to tilt towards, so b3 = e3 and F's upward part (none).
      const Eigen::Vector3d b3 =
          horizontal > 0 ? Eigen::Vector3d(std::sin(k.max_tilt_rad) * F.x() / horizontal,
                                           std::sin(k.max_tilt_rad) * F.y() / horizontal, std::cos(k.max_tilt_rad))
                         : e3;
      F = F.z() > 0 ? Eigen::Vector3d(b3 * (F.z() / b3.z())) : Eigen::Vector3d(b3 * std::max(0.0, F.dot(b3)));
      c.tilt_saturated = true;
    }
    const double F_norm = F.norm();
    const Eigen::Vector3d b3d = F_norm > 1e-9 ? Eigen::Vector3d(F / F_norm) : e3;
    Eigen::Vector3d b1c;
    bool heading_from_yaw = true;
    t.R_d = desired_attitude(b3d, ref.yaw_rad, R, b1c, heading_from_yaw);
    f = std::max(0.0, F.dot(R.col(2)));

    // Omega_d by differential flatness, from the feedforward part of F only (dF/dt ~ m j_d; the feedback
    // terms' derivatives are left out, as Omega_d-dot is): d(b3d)/dt = (I - b3d b3d^T) m j_d / |F|, and
    // with dR_d/dt = R_d hat(Omega_d), d(b3d)/dt = Omega_d,y b1d - Omega_d,x b2d, so
    // Omega_d,x = -b2d . d(b3d)/dt, Omega_d,y = b1d . d(b3d)/dt (Mellinger and Kumar's h_Omega with |F|
    // for f). Omega_d,z = b2d . d(b1d)/dt, differentiating the construction of R_d above with
    // d(b1c)/dt = yaw_rate (-sin yaw, cos yaw, 0):
    //   Omega_d,z = (yaw_rate b1c_perp . b2d - d(b3d)/dt . (b1c x b1d)) / |b3d x b1c|,
    // which is yaw_rate when b3d is vertical (Mellinger and Kumar's yaw_rate (b3d . e3) to first order).
    // The reference carries no snap, so dOmega_d/dt = 0. While the tilt limit holds b3d, Omega_d = 0.
    if (F_norm > 1e-9 && !c.tilt_saturated) {
      const Eigen::Vector3d b3d_dot = (m / F_norm) * (ref.j_W - b3d.dot(ref.j_W) * b3d);
      const Eigen::Vector3d b1d = t.R_d.col(0), b2d = t.R_d.col(1);
      const Eigen::Vector3d b1c_dot =
          heading_from_yaw ? Eigen::Vector3d(Eigen::Vector3d(-std::sin(ref.yaw_rad), std::cos(ref.yaw_rad), 0.0) *
                                             ref.yaw_rate_rad_s)
                           : Eigen::Vector3d(Eigen::Vector3d::Zero());
      const double n = b3d.cross(b1c).norm();
      t.Omega_d_B =
          Eigen::Vector3d(-b2d.dot(b3d_dot), b1d.dot(b3d_dot), (b1c_dot.dot(b2d) - b3d_dot.dot(b1c.cross(b1d))) / n);
    }
    const model::Euler e = model::euler_from_quaternion(Eigen::Quaterniond(t.R_d));
    c.roll_des_rad = e.roll_rad;
    c.pitch_des_rad = e.pitch_rad;
    c.yaw_des_rad = e.yaw_rad;
  } else {
    const Eigen::Quaterniond q_d = model::quaternion_from_euler({ref.roll_rad, ref.pitch_rad, ref.yaw_rad});
    t.R_d = q_d.toRotationMatrix();
    const double u = m * (g + ref.a_W.z()) - k.k_x.z() * t.e_x_W.z() - k.k_v.z() * t.e_v_W.z();
    f = std::max(0.0, u / std::max(R(2, 2), k.min_cos_tilt));
    c.roll_des_rad = ref.roll_rad;
    c.pitch_des_rad = ref.pitch_rad;
    c.yaw_des_rad = ref.yaw_rad;
  }

  // Attitude law: eqs. (10)-(11) and the moment of Lee, Leok and McClamroch (2010) with dOmega_d/dt = 0.
  const Eigen::Matrix3d RtRd = R.transpose() * t.R_d;
  const Eigen::Vector3d Omega_d_in_B = RtRd * t.Omega_d_B;
  t.e_R = attitude_error_vector(t.R_d, R);
  t.e_Omega_B = Omega - Omega_d_in_B;
  const Eigen::Vector3d M = -k.k_R.cwiseProduct(t.e_R) - k.k_Omega.cwiseProduct(t.e_Omega_B) + Omega.cross(J_ * Omega) -
                            J_ * (Omega.cross(Omega_d_in_B));

  Eigen::Vector4d U(f, M.x(), M.y(), M.z());
  U[3] = allocation_.rotor_count() == 4
             ? limit_yaw_torque<Eigen::Matrix4d, Eigen::Vector4d>(mixer_inverse_, U, v.motor.omega_min_rad_s,
                                                                  v.motor.omega_max_rad_s)
             : limit_yaw_torque<model::AllocationMatrix, model::RotorVector>(
                   allocation_.matrix(), U, v.motor.omega_min_rad_s, v.motor.omega_max_rad_s);
  t.yaw_torque_cut_Nm = M.z() - U[3];
  const control::Allocation a = allocation_.allocate(U, v.motor.omega_min_rad_s, v.motor.omega_max_rad_s);
  c.U = U;
  model::assign_rotors(c.omega_rad_s, a.omega_rad_s);
  c.rotor_saturated = a.saturated;
  c.attitude_error = control::attitude_error(Eigen::Quaterniond(t.R_d), obs.q_WB.normalized());

  const std::array<double, 14> values = {
      t.e_x_W.x(), t.e_x_W.y(), t.e_x_W.z(),     t.e_v_W.x(),     t.e_v_W.y(),     t.e_v_W.z(), t.e_R.x(),
      t.e_R.y(),   t.e_R.z(),   t.e_Omega_B.x(), t.e_Omega_B.y(), t.e_Omega_B.z(), f,           t.yaw_torque_cut_Nm};
  std::copy(values.begin(), values.end(), c.outputs.begin());
  terms_ = t;
}

}  // namespace quadcosim::controllers
