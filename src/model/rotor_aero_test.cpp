// Tests of the per-rotor aerodynamics (aero.rotor_aero, model/aero.hpp) against closed forms written
// here from the hub geometry: the drag of a steady translation, the moments a body rate adds, the
// inflow's thrust change in a climb, the flapping moment's direction and size, a terminal velocity
// reached in free flight, and the power of the rotor forces, which never adds energy in still air.
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>
#include <string>
#include <vector>

#include "model/quadrotor.hpp"
#include "model/random.hpp"
#include "model/vehicle_params.hpp"
#include "model/vehicle_presets.hpp"

namespace quadcosim::model {
namespace {

/// The paper's vehicle with the per-rotor terms on and the given coefficients.
VehicleParams with_rotor_aero(double k_d, double k_z, double k_flap, double k_h, RotorLayout layout) {
  VehicleParams p;
  p.layout = layout;
  p.aero.rotor_aero = RotorAero::kOn;
  p.aero.rotor_drag_k_d = k_d;
  p.aero.inflow_k_z = k_z;
  p.aero.flapping_k_flap = k_flap;
  p.aero.translational_lift_k_h = k_h;
  return p;
}

/// The hubs as the columns of a 3 x N matrix.
Eigen::Matrix3Xd hubs(const VehicleParams& p) {
  Eigen::Matrix3Xd r(3, 4);
  for (int i = 0; i < 4; ++i) r.col(i) = rotor_position_B(p, i);
  return r;
}

/// A level state moving at v_W with body rate w_B, rotors at the paper's hover speed.
State level(const Quadrotor& q, const Eigen::Vector3d& v_W, const Eigen::Vector3d& w_B) {
  State x = q.initial_state({0, 0, 50}, 0.0, true);
  x.v_W = v_W;
  x.w_B = w_B;
  return x;
}

class RotorAeroLayouts : public ::testing::TestWithParam<RotorLayout> {};

INSTANTIATE_TEST_SUITE_P(PlusAndX, RotorAeroLayouts, ::testing::Values(RotorLayout::kPlus, RotorLayout::kX));

TEST_P(RotorAeroLayouts, SteadyTranslationDragIsMinusNOmegaKdTimesTheInPlaneVelocity) {
  constexpr double kD = 3e-5, kZ = 5e-5;
  const VehicleParams p = with_rotor_aero(kD, kZ, 0.0, 0.0, GetParam());
  const Quadrotor q(p);
  const double w = p.hover_omega_rad_s();
  const Eigen::Vector3d v(3.0, -2.0, 0.0);  // level, no yaw: the body axes are the world axes
  const Environment still;
  const StateDerivative d = q.derivative(0.0, level(q, v, Eigen::Vector3d::Zero()), Vector4::Constant(w), &still);
  // Four hubs moving with the body: F = -4 w k_d (v_x, v_y, 0), thrust carrying the weight.
  EXPECT_NEAR(d.v_W.x(), -4.0 * w * kD * v.x() / p.mass_kg, 1e-12);
  EXPECT_NEAR(d.v_W.y(), -4.0 * w * kD * v.y() / p.mass_kg, 1e-12);
  EXPECT_NEAR(d.v_W.z(), 0.0, 1e-12);
  // Equal forces at hubs whose positions sum to zero: no moment.
  EXPECT_NEAR(d.w_B.norm(), 0.0, 1e-12);
}

TEST_P(RotorAeroLayouts, ABodyRateAddsHubVelocitiesAndTheirMomentsInClosedForm) {
  constexpr double kD = 3e-5, kZ = 5e-5, yaw_rate = 0.7, roll_rate = -0.4, pitch_rate = 0.9;
  const VehicleParams p = with_rotor_aero(kD, kZ, 0.0, 0.0, GetParam());
  const Eigen::Matrix3Xd r = hubs(p);
  const double L = p.arm_length_m, w = 4000.0;
  const Eigen::Vector4d omega = Eigen::Vector4d::Constant(w), eta = Eigen::Vector4d::Ones();
  const Eigen::Vector3d v(2.0, 1.0, 0.0);
  // Yaw rate r: each hub moves tangentially at r L; the in-plane drags add to a yaw damping
  // -N w k_d L^2 r and, summed, to no force beyond the translation's.
  BodyWrench m = rotor_aero_wrench_B(p.aero, r, v, {0.0, 0.0, yaw_rate}, omega, eta);
  EXPECT_NEAR(m.force_B.x(), -4.0 * w * kD * v.x(), 1e-12);
  EXPECT_NEAR(m.force_B.y(), -4.0 * w * kD * v.y(), 1e-12);
  EXPECT_NEAR(m.torque_B.z(), -4.0 * w * kD * L * L * yaw_rate, 1e-12);
  EXPECT_NEAR(m.torque_B.head<2>().norm(), 0.0, 1e-12);
  // Roll rate p: hub i moves along z_B at p y_i; the inflow term damps it with sum y_i^2 = 2 L^2
  // (both layouts): M_x = -2 w k_z L^2 p. Pitch alike with sum x_i^2 = 2 L^2.
  m = rotor_aero_wrench_B(p.aero, r, Eigen::Vector3d::Zero(), {roll_rate, 0.0, 0.0}, omega, eta);
  EXPECT_NEAR(m.torque_B.x(), -2.0 * w * kZ * L * L * roll_rate, 1e-12);
  EXPECT_NEAR(m.torque_B.y(), 0.0, 1e-12);
  EXPECT_NEAR(m.force_B.norm(), 0.0, 1e-12);
  m = rotor_aero_wrench_B(p.aero, r, Eigen::Vector3d::Zero(), {0.0, pitch_rate, 0.0}, omega, eta);
  EXPECT_NEAR(m.torque_B.y(), -2.0 * w * kZ * L * L * pitch_rate, 1e-12);
  EXPECT_NEAR(m.torque_B.x(), 0.0, 1e-12);
  // Through the plant: the yaw damping over Izz.
  const Quadrotor q(p);
  const Environment still;
  const StateDerivative d =
      q.derivative(0.0, level(q, Eigen::Vector3d::Zero(), {0, 0, yaw_rate}), Vector4::Constant(w), &still);
  EXPECT_NEAR(d.w_B.z(), -4.0 * w * kD * L * L * yaw_rate / p.Izz_kg_m2, 1e-10);
}

TEST(RotorAero, InflowTakesNKzOmegaVzFromTheThrustInAClimb) {
  constexpr double kZ = 5e-5, climb = 2.5;
  const VehicleParams p = with_rotor_aero(3e-5, kZ, 0.0, 0.0, RotorLayout::kPlus);
  const Quadrotor q(p);
  const double w = p.hover_omega_rad_s();
  const Environment still;
  StateDerivative d = q.derivative(0.0, level(q, {0, 0, climb}, Eigen::Vector3d::Zero()), Vector4::Constant(w), &still);
  EXPECT_NEAR(d.v_W.z(), -4.0 * kZ * w * climb / p.mass_kg, 1e-12);
  EXPECT_NEAR(d.v_W.head<2>().norm(), 0.0, 1e-15);
  // Descending, the thrust grows by as much; wind blowing down is a climb through the air.
  d = q.derivative(0.0, level(q, {0, 0, -climb}, Eigen::Vector3d::Zero()), Vector4::Constant(w), &still);
  EXPECT_NEAR(d.v_W.z(), 4.0 * kZ * w * climb / p.mass_kg, 1e-12);
  Environment downdraft;
  downdraft.wind_W = {0, 0, -climb};
  d = q.derivative(0.0, level(q, Eigen::Vector3d::Zero(), Eigen::Vector3d::Zero()), Vector4::Constant(w), &downdraft);
  EXPECT_NEAR(d.v_W.z(), -4.0 * kZ * w * climb / p.mass_kg, 1e-12);
}

TEST(RotorAero, FlappingPitchesTheVehicleAwayFromTheRelativeWind) {
  constexpr double kFlap = 2e-6, V = 4.0, w = 4500.0;
  const VehicleParams p = with_rotor_aero(0.0, 0.0, kFlap, 0.0, RotorLayout::kPlus);
  const Eigen::Vector4d omega = Eigen::Vector4d::Constant(w), eta = Eigen::Vector4d::Ones();
  // Forward (+x_B): M = -N k_flap w (e_z x v) = (0, -N k_flap w V, 0), a negative pitch moment: nose up.
  BodyWrench m = rotor_aero_wrench_B(p.aero, hubs(p), {V, 0, 0}, Eigen::Vector3d::Zero(), omega, eta);
  EXPECT_NEAR(m.torque_B.y(), -4.0 * kFlap * w * V, 1e-15);
  EXPECT_NEAR(m.torque_B.x(), 0.0, 1e-15);
  EXPECT_NEAR(m.torque_B.z(), 0.0, 1e-15);
  EXPECT_EQ(m.force_B, Eigen::Vector3d::Zero());
  // Sideways to the left (+y_B): a positive roll moment, the left side up, away from the wind again.
  m = rotor_aero_wrench_B(p.aero, hubs(p), {0, V, 0}, Eigen::Vector3d::Zero(), omega, eta);
  EXPECT_NEAR(m.torque_B.x(), 4.0 * kFlap * w * V, 1e-15);
  EXPECT_NEAR(m.torque_B.y(), 0.0, 1e-15);
  // Through the plant, flying forward: the pitch rate grows negative (nose up).
  const Quadrotor q(p);
  const Environment still;
  const StateDerivative d =
      q.derivative(0.0, level(q, {V, 0, 0}, Eigen::Vector3d::Zero()), Vector4::Constant(p.hover_omega_rad_s()), &still);
  EXPECT_NEAR(d.w_B.y(), -4.0 * kFlap * p.hover_omega_rad_s() * V / p.Iyy_kg_m2, 1e-12);
}

TEST(RotorAero, TranslationalLiftAddsNKhVSquaredOfThrust) {
  constexpr double kH = 0.01, V = 3.0;
  const VehicleParams p = with_rotor_aero(0.0, 0.0, 0.0, kH, RotorLayout::kX);
  const Quadrotor q(p);
  const Environment still;
  const StateDerivative d = q.derivative(0.0, level(q, {0.6 * V, 0.8 * V, 0}, Eigen::Vector3d::Zero()),
                                         Vector4::Constant(p.hover_omega_rad_s()), &still);
  EXPECT_NEAR(d.v_W.z(), 4.0 * kH * V * V / p.mass_kg, 1e-12);
  EXPECT_NEAR(d.w_B.norm(), 0.0, 1e-12);
}

TEST(RotorAero, ARotorWithoutEfficiencyAddsNoDragAndLeavesItsMomentMissing) {
  constexpr double kD = 3e-5, w = 4000.0;
  const VehicleParams p = with_rotor_aero(kD, 0.0, 0.0, 0.0, RotorLayout::kPlus);
  const Eigen::Vector3d v(2.0, 0.0, 0.0);
  const BodyWrench m = rotor_aero_wrench_B(p.aero, hubs(p), v, Eigen::Vector3d::Zero(), Eigen::Vector4d::Constant(w),
                                           Eigen::Vector4d(1.0, 0.0, 1.0, 1.0));
  EXPECT_NEAR(m.force_B.x(), -3.0 * w * kD * v.x(), 1e-12);
  // Rotor 2 (at (0, -L, 0)) is missing. The four moments would cancel, so the other three leave
  // -(r_2 x F_2) with F_2 = (-k_d w v_x, 0, 0): r_2 x F_2 = (0, 0, -L k_d w v_x), M_z = +L k_d w v_x
  // (the left hub's drag yaws the nose towards it, unbalanced).
  EXPECT_NEAR(m.torque_B.z(), p.arm_length_m * kD * w * v.x(), 1e-12);
}

TEST(RotorAero, AnyNumberOfRotorsDragsWithItsOwnCount) {
  // Six hubs on a 0.3 m circle: the same -N w k_d v, N = 6, and no moment at zero body rate.
  constexpr double kD = 2e-5, w = 3000.0;
  AeroParams a;
  a.rotor_aero = RotorAero::kOn;
  a.rotor_drag_k_d = kD;
  Eigen::Matrix3Xd r(3, 6);
  for (int i = 0; i < 6; ++i) r.col(i) = 0.3 * Eigen::Vector3d(std::cos(i * M_PI / 3), std::sin(i * M_PI / 3), 0.0);
  Eigen::VectorXd omega = Eigen::VectorXd::Constant(6, w), eta = Eigen::VectorXd::Ones(6);
  const BodyWrench m = rotor_aero_wrench_B(a, r, {1.5, -0.5, 0.0}, Eigen::Vector3d::Zero(), omega, eta);
  EXPECT_NEAR(m.force_B.x(), -6.0 * w * kD * 1.5, 1e-12);
  EXPECT_NEAR(m.force_B.y(), 6.0 * w * kD * 0.5, 1e-12);
  EXPECT_NEAR(m.torque_B.norm(), 0.0, 1e-12);
}

TEST(RotorAero, AtZeroBodyRateTheHubDragIsTheLumpedRotorDrag) {
  // k_d at the hubs and the same number as the lumped coefficient at the centre of mass give the
  // same force in the rotor plane (the lumped form has no axial term, no moment).
  constexpr double k = 1.7e-5;
  AeroParams hub;
  hub.rotor_aero = RotorAero::kOn;
  hub.rotor_drag_k_d = k;
  AeroParams lumped;
  lumped.rotor_drag_N_s_m_per_rad_s = k;
  VehicleParams p;
  const Eigen::Vector4d omega(4100.0, 4900.0, 4300.0, 5200.0);
  const Eigen::Matrix3d R = Eigen::AngleAxisd(0.4, Eigen::Vector3d(1, 2, 3).normalized()).toRotationMatrix();
  const Eigen::Vector3d v_W(2.0, -1.0, 0.5), wind_W(0.5, 0.3, 0.0);
  const Eigen::Vector3d F_B = R.transpose() * aero_force_W(lumped, R, v_W, wind_W, omega);
  const BodyWrench m = rotor_aero_wrench_B(hub, hubs(p), R.transpose() * (v_W - wind_W), Eigen::Vector3d::Zero(), omega,
                                           Eigen::Vector4d::Ones());
  EXPECT_NEAR(m.force_B.x(), F_B.x(), 1e-14);
  EXPECT_NEAR(m.force_B.y(), F_B.y(), 1e-14);
}

TEST(RotorAero, APitchedVehicleAtConstantRotorSpeedReachesTheClosedFormTerminalVelocity) {
  // Pitched nose down by theta and held there (equal rotor speeds, equal hub forces: no moment), the
  // thrust T = m g cos(theta) carries gravity's body-z part; its body-x part, g_B,x = g sin(theta),
  // drives the vehicle forward along x_B until the rotor drag N w k_d v_x balances it:
  // v_x = m g_B,x / (N w k_d), reached with the time constant m / (N w k_d).
  constexpr double kD = 4e-5, kZ = 6e-5, theta = 0.1;
  const VehicleParams p = with_rotor_aero(kD, kZ, 0.0, 0.0, RotorLayout::kPlus);
  const Quadrotor q(p);
  const double g = p.gravity_m_s2, m = p.mass_kg;
  const double w = std::sqrt(m * g * std::cos(theta) / (4.0 * p.kt_N_per_rad2_s2));
  State x;
  x.p_W = {0, 0, 100};
  x.q_WB = Eigen::Quaterniond(Eigen::AngleAxisd(theta, Eigen::Vector3d::UnitY()));
  const Eigen::Vector3d g_B = x.q_WB.toRotationMatrix().transpose() * Eigen::Vector3d(0, 0, -g);
  const double v_terminal = m * g_B.x() / (4.0 * w * kD);
  const double tau = m / (4.0 * w * kD);
  const Environment still;
  for (int k = 0; k < 6000; ++k) q.step(x, k * 0.01, Vector4::Constant(w), 0.01, 1, &still);
  ASSERT_GT(60.0 / tau, 15.0);  // settled to e^-15
  const Eigen::Vector3d v_B = x.q_WB.toRotationMatrix().transpose() * x.v_W;
  EXPECT_NEAR(v_B.x(), v_terminal, 1e-6 * std::abs(v_terminal));
  EXPECT_NEAR(v_B.y(), 0.0, 1e-12);
  EXPECT_NEAR(v_B.z(), 0.0, 1e-9);
  EXPECT_NEAR(x.q_WB.angularDistance(Eigen::Quaterniond(Eigen::AngleAxisd(theta, Eigen::Vector3d::UnitY()))), 0.0,
              1e-12);
  EXPECT_NEAR(v_terminal, m * g * std::sin(theta) / (4.0 * w * kD), 1e-12);  // g_B = (g sin, 0, -g cos)
}

TEST(RotorAero, TheRotorForcesNeverAddEnergyInStillAir) {
  // The power of the hub forces on the body, F . v + M . w = sum F_i . v_i, equals
  // -sum eta_i |w_i| (k_d (v_ix^2 + v_iy^2) + k_z v_iz^2) <= 0 (flapping and translational lift are
  // left out: they draw on the rotors' power, not on the body's motion).
  constexpr double kD = 3e-5, kZ = 5e-5;
  for (RotorLayout layout : {RotorLayout::kPlus, RotorLayout::kX}) {
    const VehicleParams p = with_rotor_aero(kD, kZ, 0.0, 0.0, layout);
    const Eigen::Matrix3Xd r = hubs(p);
    Rng rng(stream_seed(7, "/drone", "rotor_aero_power"));
    for (int n = 0; n < 1000; ++n) {
      const Eigen::Vector3d v(rng.uniform(-10, 10), rng.uniform(-10, 10), rng.uniform(-5, 5));
      const Eigen::Vector3d w_B(rng.uniform(-6, 6), rng.uniform(-6, 6), rng.uniform(-3, 3));
      Eigen::Vector4d omega, eta;
      for (int i = 0; i < 4; ++i) {
        omega[i] = rng.uniform(0.0, 12000.0);
        eta[i] = rng.uniform(0.0, 1.0);
      }
      const BodyWrench m = rotor_aero_wrench_B(p.aero, r, v, w_B, omega, eta);
      double expected = 0.0;
      for (int i = 0; i < 4; ++i) {
        const Eigen::Vector3d vi = v + w_B.cross(r.col(i));
        expected -= eta[i] * omega[i] * (kD * (vi.x() * vi.x() + vi.y() * vi.y()) + kZ * vi.z() * vi.z());
      }
      const double power = m.force_B.dot(v) + m.torque_B.dot(w_B);
      ASSERT_LE(power, 1e-12) << n;
      ASSERT_NEAR(power, expected, 1e-9 * (1.0 + std::abs(expected))) << n;
    }
  }
}

TEST(RotorAero, OffItChangesNoNumberAndThePresetsCarryTheirCoefficientsOff) {
  // Coefficients set but rotor_aero off (as the presets carry them): not active, the paper's path.
  VehicleParams p = with_rotor_aero(3e-5, 5e-5, 1e-6, 0.01, RotorLayout::kPlus);
  p.aero.rotor_aero = RotorAero::kOff;
  EXPECT_FALSE(p.aero.active());
  p.aero.rotor_aero = RotorAero::kOn;
  EXPECT_TRUE(p.aero.active());
  EXPECT_FALSE(with_rotor_aero(0.0, 0.0, 0.0, 0.0, RotorLayout::kPlus).aero.active());
  for (const VehiclePreset& preset : vehicle_presets()) {
    EXPECT_EQ(preset.params.aero.rotor_aero, RotorAero::kOff) << preset.name;
    EXPECT_FALSE(preset.params.aero.active()) << preset.name;
  }
  EXPECT_EQ(find_vehicle_preset("crazyflie2")->params.aero.rotor_drag_k_d, 10.2506e-7);
  EXPECT_EQ(find_vehicle_preset("crazyflie2")->params.aero.inflow_k_z, 7.5530e-7);
  EXPECT_EQ(find_vehicle_preset("hummingbird")->params.aero.rotor_drag_k_d, 1.19e-4);
  EXPECT_EQ(find_vehicle_preset("hummingbird")->params.aero.inflow_k_z, 2.32e-4);
}

TEST(RotorAero, EveryPresetWithRotorAeroOnStillHovers) {
  // At rest in still air no hub moves through the air: the hover is the same equilibrium.
  for (const VehiclePreset& preset : vehicle_presets()) {
    VehicleParams p = preset.params;
    p.aero.rotor_aero = RotorAero::kOn;
    const Quadrotor q(p);
    const State x = q.initial_state({0, 0, 5}, 0.3, true);
    const Environment still;
    const StateDerivative d = q.derivative(0.0, x, x.omega_rad_s, &still);
    EXPECT_NEAR(d.v_W.norm(), 0.0, 1e-12) << preset.name;
    EXPECT_NEAR(d.w_B.norm(), 0.0, 1e-12) << preset.name;
  }
}

TEST(RotorAero, TheHubDragAndTheLumpedDragTogetherAreRefused) {
  VehicleParams p = with_rotor_aero(3e-5, 0.0, 0.0, 0.0, RotorLayout::kPlus);
  p.aero.rotor_drag_N_s_m_per_rad_s = 3e-5;
  const std::string e = validate(p);
  EXPECT_NE(e.find("aero.rotor_drag_N_s_m_per_rad_s"), std::string::npos) << e;
  EXPECT_NE(e.find("aero.rotor_drag_k_d"), std::string::npos) << e;
  p.aero.rotor_aero = RotorAero::kOff;  // the hub terms off: the lumped drag alone
  EXPECT_EQ(validate(p), "");
  p.aero.rotor_aero = RotorAero::kOn;
  p.aero.rotor_drag_k_d = 0.0;  // inflow etc. at the hubs with the lumped in-plane drag: allowed
  p.aero.inflow_k_z = 5e-5;
  EXPECT_EQ(validate(p), "");
  p.aero.inflow_k_z = -1.0;
  EXPECT_NE(validate(p).find("aero.inflow_k_z must be in [0, 1]"), std::string::npos) << validate(p);
}

}  // namespace
}  // namespace quadcosim::model
