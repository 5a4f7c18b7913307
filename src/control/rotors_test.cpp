// Vehicles with any rotor count (4, 6, 8, custom): the mixer, the hover, the allocation and the
// checks, each against an independent formula (r_i = L (cos a_i, sin a_i), the closed forms of the
// minimum-norm allocation on a symmetric frame).
#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <cmath>
#include <numbers>
#include <string>

#include "control/allocation.hpp"
#include "model/mixer.hpp"
#include "model/quadrotor.hpp"
#include "model/vehicle_params.hpp"
#include "model/vehicle_presets.hpp"

namespace quadcosim::control {
namespace {

using model::RotorLayout;
using model::VehicleParams;
constexpr double kPi = std::numbers::pi;

VehicleParams with_layout(RotorLayout layout) {
  VehicleParams p;
  p.set_layout(layout);
  return p;
}

// The firefly's rotors and motors (a hexarotor-sized k_m: the paper's k_m gives a yaw torque of the
// size used below only at speeds beyond any motor) on `layout`, signs alternating.
VehicleParams firefly_on(RotorLayout layout) {
  VehicleParams p = model::find_vehicle_preset("firefly")->params;
  p.set_layout(layout);
  for (std::size_t i = 0; i < p.spin.size(); ++i) p.spin[i] = i % 2 == 0 ? 1 : -1;
  return p;
}

// Rotor i's angle: clockwise from the nose ('+' kinds) or from half a spacing counter-clockwise of it.
double angle(RotorLayout layout, int n, int i) {
  const bool plus = layout == RotorLayout::kHexPlus || layout == RotorLayout::kOctoPlus;
  return (plus ? 0.0 : kPi / n) - 2.0 * kPi * i / n;
}

TEST(Rotors, StandardLayoutsHaveTheirRotorCount) {
  EXPECT_EQ(with_layout(RotorLayout::kPlus).rotor_count, 4);
  EXPECT_EQ(with_layout(RotorLayout::kX).rotor_count, 4);
  EXPECT_EQ(with_layout(RotorLayout::kHexPlus).rotor_count, 6);
  EXPECT_EQ(with_layout(RotorLayout::kHexX).rotor_count, 6);
  EXPECT_EQ(with_layout(RotorLayout::kOctoPlus).rotor_count, 8);
  EXPECT_EQ(with_layout(RotorLayout::kOctoX).rotor_count, 8);
}

TEST(Rotors, HexAndOctoMixersAreTheHandDerivedMatrix) {
  for (RotorLayout layout : {RotorLayout::kHexPlus, RotorLayout::kHexX, RotorLayout::kOctoPlus, RotorLayout::kOctoX}) {
    SCOPED_TRACE(model::to_string(layout));
    const VehicleParams p = with_layout(layout);
    const int n = p.rotor_count;
    EXPECT_EQ(validate(p), "");
    const model::MixerMatrix M = model::mixer_matrix(p);
    ASSERT_EQ(M.cols(), n);
    const double L = p.arm_length_m, kt = p.kt_N_per_rad2_s2, km = p.km_Nm_per_rad2_s2;
    for (int i = 0; i < n; ++i) {
      const double a = angle(layout, n, i);
      // Thrust k_t w^2 along +z_B at (L cos a, L sin a): torque (L sin a, -L cos a, 0) k_t w^2.
      EXPECT_DOUBLE_EQ(M(0, i), kt);
      EXPECT_NEAR(M(1, i), kt * L * std::sin(a), 1e-15 * kt * L);
      EXPECT_NEAR(M(2, i), -kt * L * std::cos(a), 1e-15 * kt * L);
      EXPECT_DOUBLE_EQ(M(3, i), (i % 2 == 0 ? 1.0 : -1.0) * km);  // alternating, rotor 1 clockwise
    }
  }
  // The hex '+' rotor 1 sits on the nose, rotor 2 60 deg clockwise (front-right).
  const VehicleParams hex = with_layout(RotorLayout::kHexPlus);
  EXPECT_EQ(model::rotor_position_B(hex, 0), Eigen::Vector3d(hex.arm_length_m, 0.0, 0.0));
  EXPECT_NEAR(model::rotor_position_B(hex, 1).y(), -hex.arm_length_m * std::sqrt(3.0) / 2.0, 1e-15);
}

TEST(Rotors, HoverSpeedHoldsTheVehicle) {
  for (RotorLayout layout : {RotorLayout::kHexPlus, RotorLayout::kHexX, RotorLayout::kOctoPlus, RotorLayout::kOctoX}) {
    SCOPED_TRACE(model::to_string(layout));
    const VehicleParams p = with_layout(layout);
    const double hover = std::sqrt(p.mass_kg * p.gravity_m_s2 / (p.rotor_count * p.kt_N_per_rad2_s2));
    EXPECT_NEAR(p.hover_omega_rad_s(), hover, 1e-12 * hover);
    const model::Quadrotor q(p);
    const model::State x = q.initial_state({0.0, 0.0, 5.0}, 0.4, /*hover=*/true);
    ASSERT_EQ(x.omega_rad_s.size(), p.rotor_count);
    const model::StateDerivative d = q.derivative(0.0, x, x.omega_rad_s);
    EXPECT_LT(d.v_W.norm(), 1e-12);
    EXPECT_LT(d.w_B.norm(), 1e-9);
  }
}

TEST(Rotors, PseudoInverseMeetsTheWrenchWithTheLeastNorm) {
  for (RotorLayout layout : {RotorLayout::kHexX, RotorLayout::kOctoPlus}) {
    SCOPED_TRACE(model::to_string(layout));
    const VehicleParams p = firefly_on(layout);
    const model::MixerMatrix M = model::mixer_matrix(p);
    const RotorAllocation allocation(p);
    ASSERT_EQ(allocation.rotor_count(), p.rotor_count);
    const Eigen::Vector4d U(p.mass_kg * p.gravity_m_s2 * 1.1, 0.3, -0.2, 0.05);
    const model::RotorVector omega_sq = allocation.squared_speeds(U);
    // Unsaturated: the speeds make exactly the wrench asked for.
    const Eigen::Vector4d made = M * omega_sq;
    for (int r = 0; r < 4; ++r) EXPECT_NEAR(made[r], U[r], 1e-12 * std::max(1.0, std::abs(U[r])));
    // Least norm: orthogonal to every squared-speed change that makes no wrench (M's null space).
    const Eigen::MatrixXd null = Eigen::FullPivLU<Eigen::MatrixXd>(Eigen::MatrixXd(M)).kernel();
    ASSERT_EQ(null.cols(), p.rotor_count - 4);
    for (Eigen::Index c = 0; c < null.cols(); ++c) {
      EXPECT_NEAR(omega_sq.dot(null.col(c)), 0.0, 1e-9 * omega_sq.norm() * null.col(c).norm());
    }
    // Pure thrust: equal speeds, T / (N k_t) each.
    const model::RotorVector hover_sq = allocation.squared_speeds({p.mass_kg * p.gravity_m_s2, 0.0, 0.0, 0.0});
    const double each = p.mass_kg * p.gravity_m_s2 / (p.rotor_count * p.kt_N_per_rad2_s2);
    for (Eigen::Index i = 0; i < hover_sq.size(); ++i) EXPECT_NEAR(hover_sq[i], each, 1e-12 * each);
    const Allocation a = allocation.allocate(U, p.motor.omega_min_rad_s, p.motor.omega_max_rad_s);
    EXPECT_EQ(a.omega_rad_s.size(), p.rotor_count);
    EXPECT_FALSE(a.saturated.any());
    EXPECT_EQ(a.saturated.count, p.rotor_count);
  }
}

TEST(Rotors, AYawTorqueOnAHexSpreadsBySpinSign) {
  // On the symmetric hex with alternating spins the mixer's rows are orthogonal, so M^+ U gives
  // w_i^2 = T / (6 k_t) + s_i tau_z / (6 k_m).
  const VehicleParams p = firefly_on(RotorLayout::kHexX);
  const RotorAllocation allocation(p);
  const double T = p.mass_kg * p.gravity_m_s2, tau = 0.02;
  const model::RotorVector sq = allocation.squared_speeds({T, 0.0, 0.0, tau});
  for (int i = 0; i < 6; ++i) {
    const double expected =
        T / (6.0 * p.kt_N_per_rad2_s2) + p.spin[static_cast<std::size_t>(i)] * tau / (6.0 * p.km_Nm_per_rad2_s2);
    EXPECT_GT(expected, 0.0);
    EXPECT_NEAR(sq[i], expected, 1e-9 * expected) << "rotor " << i + 1;
  }
  EXPECT_GT(sq[0], sq[1]);  // rotor 1 clockwise (+1) speeds up for a positive yaw torque
}

TEST(Rotors, ASaturatedRotorIsClampedAndFlagged) {
  const VehicleParams p = with_layout(RotorLayout::kOctoX);
  const RotorAllocation allocation(p);
  const Allocation a = allocation.allocate({1e9, 0.0, 0.0, 0.0}, 0.0, p.motor.omega_max_rad_s);
  for (int i = 0; i < 8; ++i) {
    EXPECT_EQ(a.omega_rad_s[i], p.motor.omega_max_rad_s);
    EXPECT_TRUE(a.saturated[i]);
  }
}

TEST(Rotors, ACustomLayoutsMixerComesFromItsPositions) {
  VehicleParams p;
  p.layout = RotorLayout::kCustom;
  p.rotor_count = 5;
  p.rotor_positions_m = {Eigen::Vector3d(0.3, 0.1, 0.02), Eigen::Vector3d(0.1, -0.35, 0.0),
                         Eigen::Vector3d(-0.25, -0.2, 0.0), Eigen::Vector3d(-0.3, 0.25, 0.0),
                         Eigen::Vector3d(0.05, 0.4, -0.01)};
  p.spin = {1, -1, 1, -1, -1, 1, 1, 1};
  ASSERT_EQ(validate(p), "");
  const model::MixerMatrix M = model::mixer_matrix(p);
  ASSERT_EQ(M.cols(), 5);
  for (int i = 0; i < 5; ++i) {
    const Eigen::Vector3d r = p.rotor_positions_m[static_cast<std::size_t>(i)];
    const Eigen::Vector3d tau = r.cross(Eigen::Vector3d(0.0, 0.0, p.kt_N_per_rad2_s2));  // r x F per unit w^2
    EXPECT_EQ(M(0, i), p.kt_N_per_rad2_s2);
    EXPECT_NEAR(M(1, i), tau.x(), 1e-20);
    EXPECT_NEAR(M(2, i), tau.y(), 1e-20);
    EXPECT_EQ(M(3, i), p.spin[static_cast<std::size_t>(i)] * p.km_Nm_per_rad2_s2);
  }
  // Its allocation still meets a wrench exactly.
  const RotorAllocation allocation(p);
  const Eigen::Vector4d U(p.mass_kg * p.gravity_m_s2, 0.1, 0.05, -0.01);
  const Eigen::Vector4d made = M * allocation.squared_speeds(U);
  for (int r = 0; r < 4; ++r) EXPECT_NEAR(made[r], U[r], 1e-11 * std::max(1.0, std::abs(U[r])));
}

TEST(Rotors, BadRotorSetsAreRefusedByName) {
  VehicleParams hex = with_layout(RotorLayout::kHexX);
  hex.spin = {1, 1, 1, 1, 1, 1, 1, 1};  // no yaw authority: the yaw row is the thrust row scaled
  std::string e = validate(hex);
  EXPECT_NE(e.find("singular"), std::string::npos) << e;
  EXPECT_NE(e.find("hex_x"), std::string::npos) << e;

  VehicleParams custom;
  custom.layout = RotorLayout::kCustom;
  custom.rotor_count = 3;
  e = validate(custom);
  EXPECT_NE(e.find("rotor_count must be in [4, 8]"), std::string::npos) << e;
  EXPECT_NE(e.find("got 3"), std::string::npos) << e;
  custom.rotor_count = 9;
  e = validate(custom);
  EXPECT_NE(e.find("got 9"), std::string::npos) << e;

  custom.rotor_count = 4;
  custom.rotor_positions_m = {Eigen::Vector3d(0.2, 0.0, 0.0), Eigen::Vector3d(0.0, -0.2, 0.0),
                              Eigen::Vector3d(0.2, 0.0, 0.0), Eigen::Vector3d(0.0, 0.2, 0.0)};
  e = validate(custom);
  EXPECT_NE(e.find("distinct"), std::string::npos) << e;
  EXPECT_NE(e.find("rotors 1 and 3"), std::string::npos) << e;

  custom.rotor_positions_m[2] = Eigen::Vector3d(std::nan(""), 0.0, 0.0);
  e = validate(custom);
  EXPECT_NE(e.find("finite"), std::string::npos) << e;

  // All four rotors on one line: no torque about that line, whatever the spins.
  custom.rotor_positions_m = {Eigen::Vector3d(0.1, 0.0, 0.0), Eigen::Vector3d(0.2, 0.0, 0.0),
                              Eigen::Vector3d(-0.1, 0.0, 0.0), Eigen::Vector3d(-0.2, 0.0, 0.0)};
  e = validate(custom);
  EXPECT_NE(e.find("singular"), std::string::npos) << e;
  EXPECT_NE(e.find("custom"), std::string::npos) << e;

  VehicleParams wrong_count = with_layout(RotorLayout::kOctoPlus);
  wrong_count.rotor_count = 6;
  e = validate(wrong_count);
  EXPECT_NE(e.find("rotor_count must be 8 for layout octo_plus"), std::string::npos) << e;
}

TEST(Rotors, TheFireflyPresetIsRotorSsHexarotor) {
  const model::VehiclePreset* f = model::find_vehicle_preset("firefly");
  ASSERT_NE(f, nullptr);
  const VehicleParams& v = f->params;
  EXPECT_EQ(v.layout, RotorLayout::kHexX);
  EXPECT_EQ(v.rotor_count, 6);
  EXPECT_EQ(v.arm_length_m, 0.215);
  EXPECT_EQ(v.kt_N_per_rad2_s2, 8.54858e-6);
  EXPECT_EQ(v.km_Nm_per_rad2_s2, 8.54858e-6 * 0.016);
  EXPECT_EQ(v.motor.omega_max_rad_s, 838.0);
  // The 1.5 kg body and its six 5 g rotors at the hubs.
  EXPECT_NEAR(v.mass_kg, 1.53, 1e-12);
  EXPECT_NEAR(v.Izz_kg_m2, 0.0977 + 6 * 0.005 * 0.215 * 0.215, 1e-15);
  // RotorS's front-left rotor turns counter-clockwise (-1 here), the front-right one clockwise.
  EXPECT_EQ(v.spin[0], -1);
  EXPECT_EQ(v.spin[1], 1);
  EXPECT_EQ(model::validate(v), "");
  // It can lift its weight: six rotors at 838 rad/s give about 2.4 times it.
  EXPECT_GT(6.0 * v.kt_N_per_rad2_s2 * 838.0 * 838.0 / (v.mass_kg * v.gravity_m_s2), 2.0);
}

}  // namespace
}  // namespace quadcosim::control
