// Unit tests for the model library: parameters, mixer, attitude conventions and the plant's
// derivative, integrator, ground contact, motors and outputs. Every expected number is computed
// here from the paper's equations written out by hand, an analytic solution, or an independent
// Eigen construction, never by calling the function under test a second time.
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <Eigen/LU>
#include <Eigen/SVD>
#include <cmath>
#include <limits>
#include <numbers>
#include <string>
#include <vector>

#include "model/attitude.hpp"
#include "model/mixer.hpp"
#include "model/quadrotor.hpp"
#include "model/vehicle_params.hpp"

namespace {

using quadcosim::model::Euler;
using quadcosim::model::GyroscopicModel;
using quadcosim::model::MotorModel;
using quadcosim::model::Outputs;
using quadcosim::model::Quadrotor;
using quadcosim::model::RotorAero;
using quadcosim::model::RotorLayout;
using quadcosim::model::State;
using quadcosim::model::StateDerivative;
using quadcosim::model::Vector4;
using quadcosim::model::VehicleParams;

constexpr double kPi = std::numbers::pi;
constexpr double kDt = 0.01;  // [s] the plant tick (100 Hz)

// Table 1 of the paper, typed in again so the defaults are checked against the source, not
// themselves.
constexpr double kMass = 1.96, kG = 9.81, kIxx = 0.0149, kIyy = 0.0153, kIzz = 0.0532;
constexpr double kL = 0.59, kKt = 2.06e-7, kKm = 1.01e-10;

// R_WB = Rz(yaw) Ry(pitch) Rx(roll), built from Eigen's axis-angle type (independent of
// attitude.cpp).
Eigen::Matrix3d rotation_zyx(double roll, double pitch, double yaw) {
  return (Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitZ()) * Eigen::AngleAxisd(pitch, Eigen::Vector3d::UnitY()) *
          Eigen::AngleAxisd(roll, Eigen::Vector3d::UnitX()))
      .toRotationMatrix();
}

// Angle [rad] of the rotation that takes A to B.
double rotation_distance(const Eigen::Matrix3d& A, const Eigen::Matrix3d& B) {
  return Eigen::AngleAxisd(A.transpose() * B).angle();
}

// Eq. (4) written out row by row for the '+' layout: (U1, U2, U3, U4) from the four rotor speeds.
Eigen::Vector4d eq4_by_hand(const VehicleParams& p, const Vector4& w) {
  const double w1 = w[0] * w[0], w2 = w[1] * w[1], w3 = w[2] * w[2], w4 = w[3] * w[3];
  const double kt = p.kt_N_per_rad2_s2, km = p.km_Nm_per_rad2_s2, L = p.arm_length_m;
  return {kt * (w1 + w2 + w3 + w4),   // U1
          L * kt * (-w2 + w4),        // U2 (roll)
          L * kt * (-w1 + w3),        // U3 (pitch)
          km * (w1 - w2 + w3 - w4)};  // U4 (yaw)
}

State airborne_state(const Quadrotor& quad, const Eigen::Vector3d& p_W, const Euler& e, const Eigen::Vector3d& w_B) {
  State x = quad.initial_state(p_W, 0.0, false);
  x.q_WB = Eigen::Quaterniond(rotation_zyx(e.roll_rad, e.pitch_rad, e.yaw_rad));
  x.w_B = w_B;
  return x;
}

// -------------------------------------------------------------------------------------------------
// VehicleParams and validate()

TEST(VehicleParams, DefaultsAreTable1) {
  const VehicleParams p;
  EXPECT_EQ(p.mass_kg, kMass);
  EXPECT_EQ(p.gravity_m_s2, kG);
  EXPECT_EQ(p.Ixx_kg_m2, kIxx);
  EXPECT_EQ(p.Iyy_kg_m2, kIyy);
  EXPECT_EQ(p.Izz_kg_m2, kIzz);
  EXPECT_EQ(p.arm_length_m, kL);
  EXPECT_EQ(p.kt_N_per_rad2_s2, kKt);
  EXPECT_EQ(p.km_Nm_per_rad2_s2, kKm);
  EXPECT_EQ(p.layout, RotorLayout::kPlus);
  EXPECT_EQ(p.motor.model, MotorModel::kIdeal);
  EXPECT_EQ(p.gyroscopic, GyroscopicModel::kFull);
}

TEST(VehicleParams, HoverOmegaIsSqrtOfWeightOverFourKt) {
  const VehicleParams p;
  const double expected = std::sqrt(kMass * kG / (4.0 * kKt));
  EXPECT_NEAR(expected, 4830.6, 0.05);  // the figure quoted in docs/model.md
  EXPECT_NEAR(p.hover_omega_rad_s(), expected, 1e-12 * expected);
  // And it really carries the weight: 4 k_t w^2 = m g.
  EXPECT_NEAR(4.0 * kKt * p.hover_omega_rad_s() * p.hover_omega_rad_s(), kMass * kG, 1e-12);
}

TEST(Validate, DefaultsAndXLayoutAreValid) {
  VehicleParams p;
  EXPECT_EQ(quadcosim::model::validate(p), "");
  p.layout = RotorLayout::kX;
  p.motor.model = MotorModel::kFirstOrder;
  p.gyroscopic = GyroscopicModel::kSimplified;
  p.spin = {-1, +1, -1, +1};  // the mirror-image propeller set is fine too
  EXPECT_EQ(quadcosim::model::validate(p), "");
}

// The message must start with the offending field's name.
void expect_rejected(const VehicleParams& p, const std::string& field) {
  const std::string msg = quadcosim::model::validate(p);
  EXPECT_FALSE(msg.empty()) << "expected " << field << " to be rejected";
  EXPECT_EQ(msg.rfind(field, 0), 0u) << "message '" << msg << "' does not start with " << field;
}

TEST(Validate, RejectsBadNumbersNamingTheField) {
  const double nan = std::numeric_limits<double>::quiet_NaN();
  {
    VehicleParams p;
    p.mass_kg = -1.0;
    expect_rejected(p, "mass_kg");
    EXPECT_NE(quadcosim::model::validate(p).find("-1"), std::string::npos);  // quotes the bad value
  }
  {
    VehicleParams p;
    p.Ixx_kg_m2 = 0.0;
    expect_rejected(p, "Ixx_kg_m2");
  }
  {
    VehicleParams p;
    p.Iyy_kg_m2 = 0.0;
    expect_rejected(p, "Iyy_kg_m2");
  }
  {
    VehicleParams p;
    p.Izz_kg_m2 = -0.05;
    expect_rejected(p, "Izz_kg_m2");
  }
  {
    VehicleParams p;
    p.gravity_m_s2 = nan;
    expect_rejected(p, "gravity_m_s2");
  }
  {
    VehicleParams p;
    p.kt_N_per_rad2_s2 = std::numeric_limits<double>::infinity();
    expect_rejected(p, "kt_N_per_rad2_s2");
  }
  {
    VehicleParams p;
    p.arm_length_m = 0.0;
    expect_rejected(p, "arm_length_m");
  }
  {
    VehicleParams p;
    p.motor.tau_up_s = 0.0;
    expect_rejected(p, "motor.tau_up_s");
  }
  {
    VehicleParams p;
    p.motor.omega_min_rad_s = -1.0;
    expect_rejected(p, "motor.omega_min_rad_s");
  }
  {
    VehicleParams p;
    p.motor.omega_min_rad_s = 13000.0;  // above omega_max
    expect_rejected(p, "motor.omega_min_rad_s");
  }
}

TEST(Validate, RejectsBadSpinSigns) {
  {
    VehicleParams p;
    p.spin = {+1, +1, +1, +1};  // no net yaw authority, reaction torques never cancel
    expect_rejected(p, "spin");
  }
  {
    VehicleParams p;
    p.spin = {+1, -1, +2, -1};  // not a sign
    expect_rejected(p, "spin");
  }
  {
    VehicleParams p;
    p.spin = {0, -1, +1, 0};
    expect_rejected(p, "spin");
  }
  // Sum zero but not alternating: adjacent rotors turning the same way. The yaw row is then a
  // combination of the others (rank 3), for either layout, so M^-1 in the allocation does not
  // exist.
  for (RotorLayout layout : {RotorLayout::kPlus, RotorLayout::kX}) {
    for (auto spin : {std::array<int, 4>{+1, +1, -1, -1}, std::array<int, 4>{+1, -1, -1, +1}}) {
      VehicleParams p;
      p.layout = layout;
      std::copy(spin.begin(), spin.end(), p.spin.begin());
      const Eigen::Matrix4d M = quadcosim::model::mixer_matrix(p);
      Eigen::Matrix4d rows = M;
      for (int r = 0; r < 4; ++r) rows.row(r).normalize();
      EXPECT_LT(Eigen::JacobiSVD<Eigen::Matrix4d>(rows).singularValues()[3], 1e-12);
      expect_rejected(p, "spin");
    }
  }
  VehicleParams p;
  p.spin = {+1, +1, -1, -1};
  EXPECT_NE(quadcosim::model::validate(p).find("[1, 1, -1, -1]"), std::string::npos);
}

// -------------------------------------------------------------------------------------------------
// The vehicle parameter table

using quadcosim::model::find_vehicle_parameter;
using quadcosim::model::Range;
using quadcosim::model::vehicle_parameters;
using quadcosim::model::VehicleParameter;

TEST(VehicleParameterTable, DefaultsReadThroughTheTableAreTable1) {
  const VehicleParams p;
  const auto value = [&](const char* name) {
    const VehicleParameter* e = find_vehicle_parameter(name);
    EXPECT_NE(e, nullptr) << name;
    return e ? e->text(p) : std::string("(missing)");
  };
  EXPECT_EQ(value("mass_kg"), "1.96");
  EXPECT_EQ(value("gravity_m_s2"), "9.81");
  EXPECT_EQ(value("Ixx_kg_m2"), "0.0149");
  EXPECT_EQ(value("Iyy_kg_m2"), "0.0153");
  EXPECT_EQ(value("Izz_kg_m2"), "0.0532");
  EXPECT_EQ(value("arm_length_m"), "0.59");
  EXPECT_EQ(value("kt_N_per_rad2_s2"), "2.06e-07");
  EXPECT_EQ(value("km_Nm_per_rad2_s2"), "1.01e-10");
  EXPECT_EQ(value("layout"), "plus");
  EXPECT_EQ(value("spin"), "[1, -1, 1, -1]");
  EXPECT_EQ(value("gyroscopic"), "full");
  EXPECT_EQ(value("motor.model"), "ideal");
  EXPECT_EQ(value("aero.linear_drag_N_s_m.z"), "0");
  EXPECT_EQ(find_vehicle_parameter("mass"), nullptr);
  EXPECT_EQ(find_vehicle_parameter("aero.linear_drag_N_s_m"), nullptr);  // a vector is three entries
}

// Each entry binds the member its name says: write a distinct value through every numeric entry and
// read the struct back field by field (the list below is written out independently of the table).
TEST(VehicleParameterTable, EveryEntryBindsTheMemberItNames) {
  VehicleParams p;
  double next = 1.0;
  int numbers = 0;
  for (const VehicleParameter& e : vehicle_parameters()) {
    if (e.kind != VehicleParameter::Kind::kNumber) continue;
    e.ref(p) = next;
    next += 1.0;
    ++numbers;
  }
  ASSERT_EQ(numbers, 27);
  EXPECT_EQ(p.mass_kg, 1.0);
  EXPECT_EQ(p.gravity_m_s2, 2.0);
  EXPECT_EQ(p.Ixx_kg_m2, 3.0);
  EXPECT_EQ(p.Iyy_kg_m2, 4.0);
  EXPECT_EQ(p.Izz_kg_m2, 5.0);
  EXPECT_EQ(p.Ixy_kg_m2, 6.0);
  EXPECT_EQ(p.Ixz_kg_m2, 7.0);
  EXPECT_EQ(p.Iyz_kg_m2, 8.0);
  EXPECT_EQ(p.arm_length_m, 9.0);
  EXPECT_EQ(p.kt_N_per_rad2_s2, 10.0);
  EXPECT_EQ(p.km_Nm_per_rad2_s2, 11.0);
  EXPECT_EQ(p.motor.tau_up_s, 12.0);
  EXPECT_EQ(p.motor.tau_down_s, 13.0);
  EXPECT_EQ(p.motor.omega_min_rad_s, 14.0);
  EXPECT_EQ(p.motor.omega_max_rad_s, 15.0);
  EXPECT_EQ(p.aero.linear_drag_N_s_m, Eigen::Vector3d(16, 17, 18));
  EXPECT_EQ(p.aero.quadratic_drag_N_s2_m2, Eigen::Vector3d(19, 20, 21));
  EXPECT_EQ(p.aero.rotor_drag_N_s_m_per_rad_s, 22.0);
  EXPECT_EQ(p.aero.ground_effect_rotor_radius_m, 23.0);
  EXPECT_EQ(p.aero.rotor_drag_k_d, 24.0);
  EXPECT_EQ(p.aero.inflow_k_z, 25.0);
  EXPECT_EQ(p.aero.flapping_k_flap, 26.0);
  EXPECT_EQ(p.aero.translational_lift_k_h, 27.0);

  VehicleParams q;
  find_vehicle_parameter("layout")->set_choice(q, "x");
  find_vehicle_parameter("gyroscopic")->set_choice(q, "simplified");
  find_vehicle_parameter("motor.model")->set_choice(q, "first_order");
  find_vehicle_parameter("aero.rotor_aero")->set_choice(q, "true");
  EXPECT_EQ(q.aero.rotor_aero, RotorAero::kOn);
  EXPECT_EQ(q.layout, RotorLayout::kX);
  EXPECT_EQ(q.gyroscopic, GyroscopicModel::kSimplified);
  EXPECT_EQ(q.motor.model, MotorModel::kFirstOrder);
  find_vehicle_parameter("spin")->signs(q)[0] = -1;
  EXPECT_EQ(q.spin[0], -1);
}

TEST(VehicleParameterTable, YamlLayoutOfNames) {
  const VehicleParameter* m = find_vehicle_parameter("mass_kg");
  EXPECT_EQ(m->section(), "");
  EXPECT_EQ(m->key(), "mass_kg");
  EXPECT_EQ(m->component(), -1);
  const VehicleParameter* t = find_vehicle_parameter("motor.tau_up_s");
  EXPECT_EQ(t->section(), "motor");
  EXPECT_EQ(t->key(), "tau_up_s");
  EXPECT_EQ(t->component(), -1);
  const VehicleParameter* d = find_vehicle_parameter("aero.quadratic_drag_N_s2_m2.y");
  EXPECT_EQ(d->section(), "aero");
  EXPECT_EQ(d->key(), "quadratic_drag_N_s2_m2");
  EXPECT_EQ(d->component(), 1);
}

TEST(VehicleParameterTable, RangeEndsAreOpenOrClosed) {
  const Range half_open{0.0, 1.0, Range::End::kOpen, Range::End::kClosed};
  EXPECT_FALSE(half_open.contains(0.0));
  EXPECT_TRUE(half_open.contains(1e-300));
  EXPECT_TRUE(half_open.contains(1.0));
  EXPECT_FALSE(half_open.contains(std::nextafter(1.0, 2.0)));
  EXPECT_FALSE(half_open.contains(std::numeric_limits<double>::quiet_NaN()));
  EXPECT_EQ(half_open.text(), "(0, 1]");
  const Range closed_open{-2.0, 1e12, Range::End::kClosed, Range::End::kOpen};
  EXPECT_TRUE(closed_open.contains(-2.0));
  EXPECT_FALSE(closed_open.contains(1e12));
  EXPECT_EQ(closed_open.text(), "[-2, 1e+12)");
}

// Gravity was >= 0 in the YAML loader and > 0 in validate(): one range now, open at 0.
TEST(VehicleParameterTable, GravityMustBeAboveZero) {
  VehicleParams p;
  p.gravity_m_s2 = 0.0;
  expect_rejected(p, "gravity_m_s2");
  EXPECT_NE(quadcosim::model::validate(p).find("(0, 1000]"), std::string::npos) << quadcosim::model::validate(p);
  p.gravity_m_s2 = 1.62;  // the Moon
  EXPECT_EQ(quadcosim::model::validate(p), "");
}

// validate() checks every numeric entry against its declared range: just outside each end is refused,
// naming the field; the ends themselves follow their open/closed kind.
TEST(VehicleParameterTable, ValidateChecksEveryDeclaredRange) {
  for (const VehicleParameter& e : vehicle_parameters()) {
    if (e.kind != VehicleParameter::Kind::kNumber) continue;
    SCOPED_TRACE(std::string(e.name));
    for (const bool low : {true, false}) {
      const double end = low ? e.range.min : e.range.max;
      const bool open = (low ? e.range.min_end : e.range.max_end) == Range::End::kOpen;
      const double outside = std::nextafter(end, low ? -1e300 : 1e300);
      VehicleParams p;
      if (e.name == "motor.omega_max_rad_s" && low) p.motor.omega_min_rad_s = 0.0;
      // A product of inertia at the end of its range is a body only with moments that large.
      if (e.name == "Ixy_kg_m2" || e.name == "Ixz_kg_m2" || e.name == "Iyz_kg_m2") {
        p.Ixx_kg_m2 = p.Iyy_kg_m2 = p.Izz_kg_m2 = 1e7;
      }
      e.ref(p) = outside;
      expect_rejected(p, std::string(e.name));
      e.ref(p) = end;
      // omega_min at its upper end would pass omega_max: that is the cross-field rule, not the range.
      if (e.name == "motor.omega_min_rad_s" && !low) continue;
      if (open) {
        expect_rejected(p, std::string(e.name));
      } else {
        EXPECT_EQ(quadcosim::model::validate(p), "") << "end " << end;
      }
    }
    VehicleParams p;
    e.ref(p) = std::numeric_limits<double>::infinity();
    expect_rejected(p, std::string(e.name));
  }
}

// -------------------------------------------------------------------------------------------------
// Mixer

TEST(Mixer, PlusLayoutIsEq4ElementByElement) {
  const VehicleParams p;
  const Eigen::Matrix4d M = quadcosim::model::mixer_matrix(p);
  const double kt = kKt, km = kKm, L = kL;
  Eigen::Matrix4d E;
  // clang-format off
  E <<  kt,      kt,     kt,     kt,
        0.0,    -L * kt, 0.0,    L * kt,
       -L * kt,  0.0,    L * kt, 0.0,
        km,     -km,     km,    -km;
  // clang-format on
  for (int r = 0; r < 4; ++r) {
    for (int c = 0; c < 4; ++c) {
      if (E(r, c) == 0.0) {
        EXPECT_EQ(M(r, c), 0.0) << "structural zero at (" << r << "," << c << ")";
      } else {
        EXPECT_DOUBLE_EQ(M(r, c), E(r, c)) << "at (" << r << "," << c << ")";
      }
    }
  }
  // The plant's wrench() uses the same numbers.
  const Quadrotor quad(p);
  const Vector4 w(4100.0, 5300.0, 4700.0, 6100.0);
  const auto f = quad.wrench(w);
  const Eigen::Vector4d U = eq4_by_hand(p, w);
  EXPECT_NEAR(f.thrust_N, U[0], 1e-14 * std::abs(U[0]));
  for (int i = 0; i < 3; ++i) EXPECT_NEAR(f.torque_B_Nm[i], U[i + 1], 1e-14 * U.norm());
}

TEST(Mixer, RotorPositionsFollowTheLayouts) {
  VehicleParams p;
  // '+': 1 nose (+x), 2 right (-y), 3 tail (-x), 4 left (+y).
  const Eigen::Vector3d plus[4] = {{kL, 0, 0}, {0, -kL, 0}, {-kL, 0, 0}, {0, kL, 0}};
  for (int i = 0; i < 4; ++i) {
    EXPECT_LT((quadcosim::model::rotor_position_B(p, i) - plus[i]).norm(), 1e-15) << "rotor " << i + 1;
  }
  // 'x': 1 front-left, 2 front-right, 3 rear-right, 4 rear-left, all at distance L.
  p.layout = RotorLayout::kX;
  const double c = kL * std::sqrt(0.5);
  const Eigen::Vector3d x[4] = {{c, c, 0}, {c, -c, 0}, {-c, -c, 0}, {-c, c, 0}};
  for (int i = 0; i < 4; ++i) {
    EXPECT_LT((quadcosim::model::rotor_position_B(p, i) - x[i]).norm(), 1e-15) << "rotor " << i + 1;
  }
}

TEST(Mixer, InverseRoundTrip) {
  for (RotorLayout layout : {RotorLayout::kPlus, RotorLayout::kX}) {
    VehicleParams p;
    p.layout = layout;
    const Eigen::Matrix4d M = quadcosim::model::mixer_matrix(p);
    const Eigen::Matrix4d Minv = M.inverse();
    const std::vector<Vector4> speeds = {Vector4(4000, 5000, 4500, 4800), Vector4(0, 12000, 300, 9000),
                                         Vector4::Constant(p.hover_omega_rad_s())};
    for (const Vector4& w : speeds) {
      const Vector4 w2 = w.cwiseProduct(w);
      const Vector4 back = Minv * (M * w2);
      EXPECT_LT((back - w2).norm(), 1e-12 * w2.norm()) << quadcosim::model::to_string(layout);
    }
  }
}

TEST(Mixer, XLayoutHasTorquesOfRotorsAt45DegreesAndFullRank) {
  VehicleParams p;
  p.layout = RotorLayout::kX;
  const Eigen::Matrix4d M = quadcosim::model::mixer_matrix(p);
  // Thrust F = kt w^2 along +z_B at r = (rx, ry, 0) gives tau = r x F = (ry F, -rx F, 0).
  const double a = kL * std::sqrt(0.5) * kKt;  // lever arm L/sqrt(2) times k_t
  Eigen::Matrix4d E;
  // clang-format off
  E << kKt, kKt, kKt, kKt,
        a,  -a,  -a,   a,     // roll: left rotors (1, 4) push +x torque
       -a,  -a,   a,   a,     // pitch: front rotors (1, 2) push -y torque (nose up)
       kKm, -kKm, kKm, -kKm;
  // clang-format on
  EXPECT_LT((M - E).cwiseAbs().maxCoeff(), 1e-14 * a);

  // Full rank: rows normalised to unit length are in fact orthonormal for both layouts, so every
  // singular value is 1 (the mixer is as well conditioned as a 4x4 allocation can be).
  for (RotorLayout layout : {RotorLayout::kPlus, RotorLayout::kX}) {
    p.layout = layout;
    Eigen::Matrix4d rows = quadcosim::model::mixer_matrix(p);
    for (int r = 0; r < 4; ++r) rows.row(r).normalize();
    const Eigen::Vector4d sv = Eigen::JacobiSVD<Eigen::Matrix4d>(rows).singularValues();
    EXPECT_NEAR(sv[0], 1.0, 1e-12);
    EXPECT_NEAR(sv[3], 1.0, 1e-12);
    EXPECT_EQ(Eigen::FullPivLU<Eigen::Matrix4d>(quadcosim::model::mixer_matrix(p)).rank(), 4);
  }
}

// -------------------------------------------------------------------------------------------------
// Attitude conventions

std::vector<double> grid(double lo, double hi, int n) {
  std::vector<double> v;
  for (int i = 0; i < n; ++i) v.push_back(lo + (hi - lo) * i / (n - 1));
  return v;
}

TEST(Attitude, QuaternionFromEulerMatchesRzRyRx) {
  for (double roll : grid(-3.1, 3.1, 9)) {
    for (double pitch : grid(-1.5, 1.5, 7)) {
      for (double yaw : grid(-3.1, 3.1, 9)) {
        const Eigen::Quaterniond q = quadcosim::model::quaternion_from_euler({roll, pitch, yaw});
        EXPECT_NEAR(q.norm(), 1.0, 1e-15);
        const Eigen::Matrix3d R = rotation_zyx(roll, pitch, yaw);
        EXPECT_LT((q.toRotationMatrix() - R).cwiseAbs().maxCoeff(), 1e-14) << roll << " " << pitch << " " << yaw;

        // The paper's eq. (3), C_{fru/enu} (world -> body), is the transpose of R_WB.
        const double cf = std::cos(roll), sf = std::sin(roll), ct = std::cos(pitch), st = std::sin(pitch),
                     cp = std::cos(yaw), sp = std::sin(yaw);
        Eigen::Matrix3d C;
        // clang-format off
        C << ct * cp,                ct * sp,                -st,
             sf * st * cp - cf * sp, sf * st * sp + cf * cp, sf * ct,
             cf * st * cp + sf * sp, cf * st * sp - sf * cp, cf * ct;
        // clang-format on
        EXPECT_LT((q.toRotationMatrix().transpose() - C).cwiseAbs().maxCoeff(), 1e-14);
      }
    }
  }
}

TEST(Attitude, EulerRoundTripAwayFromGimbalLock) {
  for (double roll : grid(-3.1, 3.1, 11)) {
    for (double pitch : grid(-1.5, 1.5, 9)) {
      for (double yaw : grid(-3.1, 3.1, 11)) {
        // From the model's own quaternion and from Eigen's axis-angle product (independent), in
        // both signs (q and -q are the same rotation) and unnormalised (the input is normalised).
        const Eigen::Quaterniond qa = quadcosim::model::quaternion_from_euler({roll, pitch, yaw});
        const Eigen::Quaterniond qb(rotation_zyx(roll, pitch, yaw));
        Eigen::Quaterniond qc = qb;
        qc.coeffs() *= -2.5;
        for (const auto& q : {qa, qb, qc}) {
          const Euler e = quadcosim::model::euler_from_quaternion(q);
          EXPECT_NEAR(quadcosim::model::wrap_pi(e.roll_rad - roll), 0.0, 1e-12);
          EXPECT_NEAR(e.pitch_rad, pitch, 1e-12);
          EXPECT_NEAR(quadcosim::model::wrap_pi(e.yaw_rad - yaw), 0.0, 1e-12);
          EXPECT_LE(std::abs(e.roll_rad), kPi);
          EXPECT_LE(std::abs(e.yaw_rad), kPi);
        }
      }
    }
  }
}

TEST(Attitude, GimbalLockReproducesTheRotation) {
  for (double sign : {+1.0, -1.0}) {
    const double pitch = sign * kPi / 2.0;
    for (double roll : {-2.0, -0.5, 0.0, 0.7, 3.0}) {
      for (double yaw : {-3.0, -1.0, 0.0, 1.2, 2.5}) {
        const Eigen::Matrix3d R = rotation_zyx(roll, pitch, yaw);
        for (const Eigen::Quaterniond& q :
             {quadcosim::model::quaternion_from_euler({roll, pitch, yaw}), Eigen::Quaterniond(R)}) {
          const Euler e = quadcosim::model::euler_from_quaternion(q);
          EXPECT_DOUBLE_EQ(e.pitch_rad, pitch);
          EXPECT_EQ(e.roll_rad, 0.0);
          // Rz(psi) Ry(+-pi/2) Rx(phi) = Rz(psi -+ phi) Ry(+-pi/2): only yaw -+ roll is defined.
          EXPECT_NEAR(quadcosim::model::wrap_pi(e.yaw_rad - (yaw - sign * roll)), 0.0, 1e-12);
          EXPECT_LT(rotation_distance(rotation_zyx(e.roll_rad, e.pitch_rad, e.yaw_rad), R), 1e-12);
        }
      }
    }
  }
}

TEST(Attitude, NearGimbalLockStaysAFaithfulRotation) {
  // Within cos(pitch) < 1.5e-8 the conversion snaps to the lock branch (error ~ cos(pitch)); outside
  // it roll and yaw lose about eps/cos(pitch). Either way the angles must rebuild the rotation to
  // ~sqrt(eps): 5e-8 leaves a factor of 3 over the worst case at the switch.
  for (double delta : {1e-3, 1e-5, 2e-6, 1e-6, 3e-8, 1.6e-8, 1.4e-8, 1e-8, 1e-10}) {
    for (double sign : {+1.0, -1.0}) {
      const double pitch = sign * (kPi / 2.0 - delta);
      const Eigen::Matrix3d R = rotation_zyx(0.8, pitch, -2.1);
      const Euler e = quadcosim::model::euler_from_quaternion(Eigen::Quaterniond(R));
      EXPECT_LT(rotation_distance(rotation_zyx(e.roll_rad, e.pitch_rad, e.yaw_rad), R), 5e-8) << "delta " << delta;
    }
  }
}

TEST(Attitude, DegenerateQuaternionGivesZeros) {
  const Euler z = quadcosim::model::euler_from_quaternion(Eigen::Quaterniond(0, 0, 0, 0));
  EXPECT_EQ(z.roll_rad, 0.0);
  EXPECT_EQ(z.pitch_rad, 0.0);
  EXPECT_EQ(z.yaw_rad, 0.0);
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const Euler n = quadcosim::model::euler_from_quaternion(Eigen::Quaterniond(nan, 0, 0, 0));
  EXPECT_EQ(n.roll_rad, 0.0);
  EXPECT_EQ(n.pitch_rad, 0.0);
  EXPECT_EQ(n.yaw_rad, 0.0);
}

TEST(WrapPi, ExactValues) {
  using quadcosim::model::wrap_pi;
  EXPECT_EQ(wrap_pi(0.0), 0.0);
  EXPECT_EQ(wrap_pi(1.0), 1.0);
  EXPECT_EQ(wrap_pi(-1.0), -1.0);
  EXPECT_EQ(wrap_pi(kPi), kPi);   // the interval is (-pi, pi]: +pi stays
  EXPECT_EQ(wrap_pi(-kPi), kPi);  // and -pi maps to +pi
  EXPECT_EQ(wrap_pi(2.0 * kPi), 0.0);
  EXPECT_EQ(wrap_pi(-2.0 * kPi), 0.0);
  EXPECT_NEAR(wrap_pi(7.0), 7.0 - 2.0 * kPi, 1e-15);
  EXPECT_NEAR(wrap_pi(-7.0), -7.0 + 2.0 * kPi, 1e-15);
  EXPECT_NEAR(wrap_pi(1.5 * kPi), -0.5 * kPi, 1e-15);
  EXPECT_NEAR(wrap_pi(-1.5 * kPi), 0.5 * kPi, 1e-15);
  EXPECT_TRUE(std::isnan(wrap_pi(std::numeric_limits<double>::quiet_NaN())));
}

TEST(WrapPi, AgreesWithAtan2OfSinCos) {
  using quadcosim::model::wrap_pi;
  for (double a = -60.0; a <= 60.0; a += 0.0137) {
    const double w = wrap_pi(a);
    EXPECT_GT(w, -kPi);
    EXPECT_LE(w, kPi);
    const double ref = std::atan2(std::sin(a), std::cos(a));  // independent formulation
    if (kPi - std::abs(ref) > 1e-9) {
      EXPECT_NEAR(w, ref, 1e-12) << a;
    }
    // a - w is a whole number of turns
    const double turns = (a - w) / (2.0 * kPi);
    EXPECT_NEAR(turns, std::round(turns), 1e-12);
  }
}

// -------------------------------------------------------------------------------------------------
// Plant: hover, free fall, ground contact

TEST(Hover, ZeroAccelerationAndStaysPutFor10s) {
  for (RotorLayout layout : {RotorLayout::kPlus, RotorLayout::kX}) {
    VehicleParams p;
    p.layout = layout;
    const Quadrotor quad(p);
    const double w_h = std::sqrt(kMass * kG / (4.0 * kKt));
    State x = quad.initial_state({1.0, -2.0, 5.0}, 0.7, true);
    ASSERT_NEAR(x.omega_rad_s.maxCoeff(), w_h, 1e-9);
    ASSERT_NEAR(x.omega_rad_s.minCoeff(), w_h, 1e-9);
    const State x0 = x;

    const StateDerivative d = quad.derivative(0.0, x, x.omega_rad_s);
    // U1/m - g is zero up to an ulp of g (4 k_t w_h^2 rounds); the torques of a symmetric layout
    // at four equal speeds cancel exactly.
    EXPECT_LT(d.v_W.norm(), 1e-14);
    EXPECT_EQ(d.w_B, Eigen::Vector3d::Zero()) << quadcosim::model::to_string(layout);
    EXPECT_EQ(d.p_W.norm(), 0.0);
    EXPECT_EQ(d.q_WB_wxyz.norm(), 0.0);

    for (int k = 0; k < 1000; ++k) quad.step(x, k * kDt, x0.omega_rad_s, kDt, 1);
    // That ulp residual integrates to at most 0.5 * 2e-15 * 10^2 = 1e-13 m over 10 s.
    EXPECT_LT((x.p_W - x0.p_W).norm(), 1e-11) << quadcosim::model::to_string(layout);
    EXPECT_LT(x.v_W.norm(), 1e-12);
    EXPECT_EQ(x.w_B, Eigen::Vector3d::Zero());
    EXPECT_LT(x.q_WB.angularDistance(x0.q_WB), 1e-15);
  }
}

TEST(Hover, FirstOrderMotorsAtHoverAreAnEquilibrium) {
  VehicleParams p;
  p.motor.model = MotorModel::kFirstOrder;
  const Quadrotor quad(p);
  State x = quad.initial_state({0.0, 0.0, 5.0}, -1.3, true);
  const State x0 = x;
  for (int k = 0; k < 1000; ++k) quad.step(x, k * kDt, x0.omega_rad_s, kDt, 1);
  EXPECT_LT((x.p_W - x0.p_W).norm(), 1e-10);
  EXPECT_EQ(x.omega_rad_s, x0.omega_rad_s);
}

TEST(FreeFall, FollowsParabolaThenRestsOnGround) {
  for (int substeps : {1, 3}) {
    const VehicleParams p;
    const Quadrotor quad(p);
    State x = quad.initial_state({3.0, -4.0, 100.0}, 0.2, false);
    x.v_W = {1.0, -0.5, 0.0};
    const Vector4 off = Vector4::Zero();
    const double t_hit = std::sqrt(2.0 * 100.0 / kG);  // ~4.515 s
    bool landed = false;
    double x_land = 0.0, y_land = 0.0;
    for (int k = 1; k <= 700; ++k) {
      quad.step(x, (k - 1) * kDt, off, kDt, substeps);
      const double t = k * kDt;
      ASSERT_GE(x.p_W.z(), 0.0) << "below ground at t=" << t;
      if (t < t_hit) {
        // RK4 integrates a quadratic exactly; only rounding remains.
        EXPECT_NEAR(x.p_W.z(), 100.0 - 0.5 * kG * t * t, 1e-9) << t;
        EXPECT_NEAR(x.v_W.z(), -kG * t, 1e-9) << t;
        EXPECT_NEAR(x.p_W.x(), 3.0 + 1.0 * t, 1e-9);
        EXPECT_NEAR(x.p_W.y(), -4.0 - 0.5 * t, 1e-9);
      } else {
        if (!landed) {
          landed = true;
          x_land = x.p_W.x();
          y_land = x.p_W.y();
        }
        // Inelastic impact, friction holds it: exactly at rest on z = 0.
        EXPECT_EQ(x.p_W.z(), 0.0) << t;
        EXPECT_EQ(x.v_W, Eigen::Vector3d::Zero()) << t;
        EXPECT_EQ(x.w_B, Eigen::Vector3d::Zero()) << t;
        EXPECT_EQ(x.p_W.x(), x_land);
        EXPECT_EQ(x.p_W.y(), y_land);
      }
    }
    EXPECT_TRUE(landed);
    // It touched down within one tick of the analytic impact time, near the analytic spot.
    EXPECT_NEAR(x_land, 3.0 + t_hit, 1.0 * kDt + 1e-9);
  }
}

TEST(GroundContact, LandedAtRestStaysExactlyAtRestBelowHover) {
  const VehicleParams p;
  const Quadrotor quad(p);
  const double w_h = std::sqrt(kMass * kG / (4.0 * kKt));
  const double d = 0.05 * w_h * w_h;
  const std::vector<Vector4> commands = {
      Vector4::Zero(),
      Vector4::Constant(0.9 * w_h),
      Vector4::Constant(w_h * (1.0 - 1e-9)),
      // sub-hover with a roll and a yaw torque: friction holds the airframe, nothing rotates
      Vector4(0.9 * w_h, std::sqrt(0.81 * w_h * w_h - d), 0.9 * w_h, std::sqrt(0.81 * w_h * w_h + d)),
      Vector4(0.95 * w_h, 0.8 * w_h, 0.95 * w_h, 0.8 * w_h),
  };
  for (const Vector4& cmd : commands) {
    State x = quad.initial_state({2.0, 3.0, 0.0}, 0.4, false);
    const State x0 = x;
    for (int k = 0; k < 300; ++k) {
      quad.step(x, k * kDt, cmd, kDt, 1);
      ASSERT_EQ(x.p_W, x0.p_W) << cmd.transpose();
      ASSERT_EQ(x.v_W, Eigen::Vector3d::Zero());
      ASSERT_EQ(x.w_B, Eigen::Vector3d::Zero());
    }
    EXPECT_LT(x.q_WB.angularDistance(x0.q_WB), 1e-15);
  }
}

TEST(GroundContact, AboveHoverLiftsOffWithAnalyticAcceleration) {
  const VehicleParams p;
  const Quadrotor quad(p);
  const double w = 1.1 * std::sqrt(kMass * kG / (4.0 * kKt));
  const double a = 4.0 * kKt * w * w / kMass - kG;  // = (1.21 - 1) g
  ASSERT_GT(a, 0.0);
  State x = quad.initial_state({0.0, 0.0, 0.0}, 1.0, false);
  for (int k = 1; k <= 100; ++k) {
    quad.step(x, (k - 1) * kDt, Vector4::Constant(w), kDt, 1);
    const double t = k * kDt;
    EXPECT_NEAR(x.p_W.z(), 0.5 * a * t * t, 1e-10) << t;
    EXPECT_NEAR(x.v_W.z(), a * t, 1e-10) << t;
  }
  EXPECT_EQ(x.p_W.x(), 0.0);
  EXPECT_EQ(x.p_W.y(), 0.0);
}

// -------------------------------------------------------------------------------------------------
// Plant: torques and forces against eqs. (4), (7), (10), (11) written out by hand

TEST(TorqueResponse, PureRollPitchYawTorquesGiveUOverI) {
  const VehicleParams p;
  const Quadrotor quad(p);
  const double wh2 = kMass * kG / (4.0 * kKt);  // hover w^2
  const double d = 0.03 * wh2;
  const double hi = std::sqrt(wh2 + d), lo = std::sqrt(wh2 - d), mid = std::sqrt(wh2);
  struct Case {
    const char* name;
    Vector4 w;
    int axis;
    double inertia;
  };
  const Case cases[] = {
      {"roll: rotor 4 (left) up, rotor 2 (right) down", Vector4(mid, lo, mid, hi), 0, kIxx},
      {"pitch: rotor 3 (tail) up, rotor 1 (nose) down", Vector4(lo, mid, hi, mid), 1, kIyy},
      {"yaw: rotors 1, 3 up, 2, 4 down", Vector4(hi, lo, hi, lo), 2, kIzz},
  };
  for (const Case& c : cases) {
    const State x = airborne_state(quad, {0, 0, 50}, {0.2, -0.1, 0.5}, Eigen::Vector3d::Zero());
    const StateDerivative dx = quad.derivative(0.0, x, c.w);
    const Eigen::Vector4d U = eq4_by_hand(p, c.w);
    const double expected = U[c.axis + 1] / c.inertia;
    EXPECT_GT(expected, 0.0) << c.name;
    for (int i = 0; i < 3; ++i) {
      EXPECT_NEAR(dx.w_B[i], i == c.axis ? expected : 0.0, 1e-12 * std::abs(expected)) << c.name << " component " << i;
    }
    // The thrust is unchanged (sum of w^2 is the hover value): the linear acceleration is that of
    // hover thrust tilted by the attitude, g (R_WB e_z - e_z).
    EXPECT_NEAR(U[0], kMass * kG, 1e-12);
    const Eigen::Vector3d a_expected = kG * (rotation_zyx(0.2, -0.1, 0.5).col(2) - Eigen::Vector3d::UnitZ());
    EXPECT_LT((dx.v_W - a_expected).norm(), 1e-12) << c.name;
  }
}

TEST(TorqueResponse, GyroscopicCouplingIsEq10AndDroppedInEq11) {
  const Vector4 w(5100.0, 4300.0, 4700.0, 5600.0);
  const Eigen::Vector3d wb(1.3, -0.7, 2.1);
  for (GyroscopicModel g : {GyroscopicModel::kFull, GyroscopicModel::kSimplified}) {
    VehicleParams p;
    p.gyroscopic = g;
    const Quadrotor quad(p);
    const State x = airborne_state(quad, {0, 0, 50}, {0.3, 0.2, -1.0}, wb);
    const StateDerivative dx = quad.derivative(0.0, x, w);
    const Eigen::Vector4d U = eq4_by_hand(p, w);
    const double P = wb.x(), Q = wb.y(), R = wb.z();
    const bool full = g == GyroscopicModel::kFull;
    // Eq. (10); eq. (11) without the products of rates.
    const Eigen::Vector3d expected((U[1] + (full ? (kIyy - kIzz) * Q * R : 0.0)) / kIxx,
                                   (U[2] + (full ? (kIzz - kIxx) * P * R : 0.0)) / kIyy,
                                   (U[3] + (full ? (kIxx - kIyy) * P * Q : 0.0)) / kIzz);
    EXPECT_LT((dx.w_B - expected).norm(), 1e-12 * expected.norm()) << quadcosim::model::to_string(g);
  }
}

TEST(TranslationalDynamics, MatchesEq7AtTiltedAttitudes) {
  const VehicleParams p;
  const Quadrotor quad(p);
  const Vector4 w(5000.0, 4700.0, 5200.0, 4900.0);
  const double U1 = eq4_by_hand(p, w)[0];
  const Euler attitudes[] = {{0.0, 0.0, 0.0},  {0.3, -0.2, 1.0}, {-0.5, 0.4, -2.0},
                             {1.2, -0.9, 2.8}, {-2.5, 1.3, 0.1}, {0.0, 0.6, -3.0}};
  for (const Euler& e : attitudes) {
    State x = airborne_state(quad, {1, 2, 30}, e, {0.4, -0.3, 0.9});
    x.v_W = {2.0, -1.0, 0.5};
    const StateDerivative dx = quad.derivative(0.0, x, w);
    const double cf = std::cos(e.roll_rad), sf = std::sin(e.roll_rad);
    const double ct = std::cos(e.pitch_rad), st = std::sin(e.pitch_rad);
    const double cp = std::cos(e.yaw_rad), sp = std::sin(e.yaw_rad);
    // Eq. (7)
    const double xdd = U1 / kMass * (cp * st * cf + sp * sf);
    const double ydd = U1 / kMass * (sp * st * cf - cp * sf);
    const double zdd = U1 / kMass * (ct * cf) - kG;
    EXPECT_NEAR(dx.v_W.x(), xdd, 1e-12) << e.roll_rad << " " << e.pitch_rad << " " << e.yaw_rad;
    EXPECT_NEAR(dx.v_W.y(), ydd, 1e-12);
    EXPECT_NEAR(dx.v_W.z(), zdd, 1e-12);
    EXPECT_EQ(dx.p_W, x.v_W);  // eq. (6): position rate is the world velocity
  }
}

TEST(AttitudeKinematics, QuaternionRateIsHalfQTimesOmega) {
  const VehicleParams p;
  const Quadrotor quad(p);
  const Eigen::Vector3d wb(0.7, -1.9, 0.4);
  const State x = airborne_state(quad, {0, 0, 10}, {0.4, -0.6, 2.2}, wb);
  const StateDerivative dx = quad.derivative(0.0, x, Vector4::Zero());
  // Eigen's own Hamilton product, 1/2 q (x) (0, w).
  const Eigen::Quaterniond prod = x.q_WB * Eigen::Quaterniond(0.0, wb.x(), wb.y(), wb.z());
  const Eigen::Vector4d expected(0.5 * prod.w(), 0.5 * prod.x(), 0.5 * prod.y(), 0.5 * prod.z());
  EXPECT_LT((dx.q_WB_wxyz - expected).norm(), 1e-15);
}

// -------------------------------------------------------------------------------------------------
// Motors

// RK4 amplification factor for y' = -y/tau over one step h: the Taylor series of exp(-z) to z^4.
double rk4_factor(double z) { return 1.0 - z + z * z / 2.0 - z * z * z / 6.0 + z * z * z * z / 24.0; }

TEST(MotorLag, SpinUpAndSpinDownFollowTheirTimeConstants) {
  VehicleParams p;
  p.motor.model = MotorModel::kFirstOrder;
  const double tau_up = p.motor.tau_up_s, tau_down = p.motor.tau_down_s;
  ASSERT_NE(tau_up, tau_down);
  const Quadrotor quad(p);
  // substeps 1 is the plant's default (h / tau_up = 0.5, where one RK4 step is off exp(-0.5) by
  // 2.4e-4 relative, and n steps by at most n R^(n-1) that much < 3e-4); with 10 substeps the
  // per-step error is (0.05)^5/120 = 2.6e-9 and the accumulated one < 1e-7.
  for (const auto& [substeps, rel_tol] : {std::pair{1, 5e-4}, std::pair{10, 1e-7}}) {
    const double h = kDt / substeps;
    // Rotors 1, 2 spin up 0 -> 6000; rotors 3, 4 spin down 8000 -> 2000; all at the same time.
    State x = quad.initial_state({0, 0, 1e4}, 0.0, false);
    x.omega_rad_s = Vector4(0.0, 0.0, 8000.0, 8000.0);
    const Vector4 cmd(6000.0, 6000.0, 2000.0, 2000.0);
    for (int k = 1; k <= 30; ++k) {
      quad.step(x, (k - 1) * kDt, cmd, kDt, substeps);
      const double t = k * kDt;
      const int n = k * substeps;
      const double up = 6000.0 * (1.0 - std::exp(-t / tau_up));
      const double down = 2000.0 + 6000.0 * std::exp(-t / tau_down);
      EXPECT_NEAR(x.omega_rad_s[0], up, rel_tol * 6000.0) << "t=" << t << " substeps " << substeps;
      EXPECT_NEAR(x.omega_rad_s[1], up, rel_tol * 6000.0);
      EXPECT_NEAR(x.omega_rad_s[2], down, rel_tol * 6000.0) << "t=" << t;
      EXPECT_NEAR(x.omega_rad_s[3], down, rel_tol * 6000.0);
      // The linear ODE makes RK4 an exact geometric sequence: w_n = c + (w_0 - c) R(h/tau)^n.
      EXPECT_NEAR(x.omega_rad_s[0], 6000.0 * (1.0 - std::pow(rk4_factor(h / tau_up), n)), 1e-9);
      EXPECT_NEAR(x.omega_rad_s[2], 2000.0 + 6000.0 * std::pow(rk4_factor(h / tau_down), n), 1e-9);
    }
  }
}

TEST(MotorLag, ThrustFollowsTheActualNotTheCommandedSpeed) {
  VehicleParams p;
  p.motor.model = MotorModel::kFirstOrder;
  const Quadrotor quad(p);
  const State x = quad.initial_state({0, 0, 10}, 0.0, false);  // rotors stopped
  const StateDerivative dx = quad.derivative(0.0, x, Vector4::Constant(8000.0));
  EXPECT_EQ(dx.v_W, Eigen::Vector3d(0, 0, -kG));
  EXPECT_NEAR(dx.omega_rad_s[0], 8000.0 / p.motor.tau_up_s, 1e-9);
}

TEST(MotorLag, SpeedsStayWithinLimits) {
  VehicleParams p;
  p.motor.model = MotorModel::kFirstOrder;
  p.motor.omega_min_rad_s = 300.0;
  p.motor.omega_max_rad_s = 8000.0;
  const Quadrotor quad(p);
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const double inf = std::numeric_limits<double>::infinity();
  // initial_state() with rotors stopped starts at 0 rad/s, below omega_min: one tick later the
  // speeds are already inside the limits.
  State x = quad.initial_state({0, 0, 1e4}, 0.0, false);
  ASSERT_EQ(x.omega_rad_s, Vector4::Zero());
  quad.step(x, 0.0, Vector4::Constant(300.0), kDt, 1);
  EXPECT_EQ(x.omega_rad_s, Vector4::Constant(300.0));
  x.omega_rad_s = Vector4::Constant(4000.0);
  for (int k = 0; k < 100; ++k) {
    quad.step(x, k * kDt, Vector4(20000.0, inf, 8000.0, 7999.0), kDt, 1);
    EXPECT_LE(x.omega_rad_s.maxCoeff(), 8000.0);
    EXPECT_GE(x.omega_rad_s.minCoeff(), 300.0);
  }
  EXPECT_NEAR(x.omega_rad_s[0], 8000.0, 1e-6);  // it saturates at the ceiling after 50 tau
  for (int k = 0; k < 100; ++k) {
    quad.step(x, k * kDt, Vector4(-100.0, nan, 0.0, -inf), kDt, 1);
    EXPECT_LE(x.omega_rad_s.maxCoeff(), 8000.0);
    EXPECT_GE(x.omega_rad_s.minCoeff(), 300.0);
  }
  EXPECT_NEAR(x.omega_rad_s[0], 300.0, 1e-6);
  EXPECT_TRUE(x.p_W.allFinite() && x.v_W.allFinite() && x.w_B.allFinite());
}

TEST(ClampCommand, ClampsAndReplacesNonFiniteWithOmegaMin) {
  VehicleParams p;
  p.motor.omega_min_rad_s = 100.0;
  p.motor.omega_max_rad_s = 9000.0;
  const Quadrotor quad(p);
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const double inf = std::numeric_limits<double>::infinity();
  EXPECT_EQ(quad.clamp_command(Vector4(-5.0, 20000.0, nan, 3000.0)), Vector4(100.0, 9000.0, 100.0, 3000.0));
  EXPECT_EQ(quad.clamp_command(Vector4(inf, -inf, 100.0, 9000.0)), Vector4(100.0, 100.0, 100.0, 9000.0));

  // The ideal motor takes the clamped command as its speed.
  State x = quad.initial_state({0, 0, 100}, 0.0, false);
  quad.step(x, 0.0, Vector4(nan, 1e6, 50.0, 4000.0), kDt, 1);
  EXPECT_EQ(x.omega_rad_s, Vector4(100.0, 9000.0, 100.0, 4000.0));
  EXPECT_TRUE(x.p_W.allFinite() && x.v_W.allFinite() && x.w_B.allFinite());
}

// -------------------------------------------------------------------------------------------------
// Outputs

TEST(SpecificForce, HoverReadsGUpInBodyAtAnyAttitude) {
  const VehicleParams p;
  const Quadrotor quad(p);
  const double w_h = std::sqrt(kMass * kG / (4.0 * kKt));
  for (const Euler& e : {Euler{0, 0, 0}, Euler{0, 0, 2.0}, Euler{0.4, -0.3, 1.0}}) {
    const State x = airborne_state(quad, {0, 0, 5}, e, Eigen::Vector3d::Zero());
    const Outputs y = quad.outputs(0.0, x, Vector4::Constant(w_h));
    // Gravity does not register; the rotors' thrust U1/m = g along +z_B does.
    EXPECT_LT((y.specific_force_B - Eigen::Vector3d(0, 0, kG)).norm(), 1e-12);
    EXPECT_EQ(y.p_W, x.p_W);
    EXPECT_EQ(y.w_B, x.w_B);
  }
}

TEST(SpecificForce, FreeFallReadsZero) {
  const VehicleParams p;
  const Quadrotor quad(p);
  const State x = airborne_state(quad, {0, 0, 50}, {0.5, 0.2, -1.0}, {1.0, 2.0, -0.5});
  const Outputs y = quad.outputs(0.0, x, Vector4::Zero());
  EXPECT_LT(y.specific_force_B.norm(), 1e-15);
}

TEST(SpecificForce, RestingOnGroundReadsGravityReactionInBody) {
  const VehicleParams p;
  const Quadrotor quad(p);
  for (const Euler& e : {Euler{0, 0, 0.8}, Euler{0.1, 0.05, -2.0}}) {
    const State x = airborne_state(quad, {4, 5, 0}, e, Eigen::Vector3d::Zero());
    const Outputs y = quad.outputs(0.0, x, Vector4::Zero());
    // R_BW (0, 0, g) is g times the third column of eq. (3)'s C_{fru/enu}.
    const double cf = std::cos(e.roll_rad), sf = std::sin(e.roll_rad);
    const double ct = std::cos(e.pitch_rad), st = std::sin(e.pitch_rad);
    const Eigen::Vector3d expected = kG * Eigen::Vector3d(-st, sf * ct, cf * ct);
    EXPECT_LT((y.specific_force_B - expected).norm(), 1e-14);
  }
}

}  // namespace

namespace {

// The plant written out independently of model/quadrotor.cpp, as a textbook would: an Eigen state
// vector (p, v, q as w x y z, w_B, rotor speeds), each rotor's thrust k_t w^2 at its arm position
// r_i = L (cos a_i, sin a_i, 0) and reaction torque spin_i k_m w^2, R(q) from Eigen's quaternion,
// q' = 1/2 q (x) (0, w), classical RK4 with the quaternion normalised after each step. No ground
// (the flight below stays high above it).
using Vec17 = Eigen::Matrix<double, 17, 1>;

Vec17 textbook_derivative(const VehicleParams& p, const Vec17& x, const Vector4& cmd) {
  const bool lag = p.motor.model == MotorModel::kFirstOrder;
  const Vector4 w = lag ? Vector4(x.segment<4>(13)) : cmd;
  double thrust = 0.0;
  Eigen::Vector3d tau = Eigen::Vector3d::Zero();
  for (int i = 0; i < 4; ++i) {
    const double a = (p.layout == RotorLayout::kPlus ? 0.0 : std::numbers::pi / 4.0) - i * std::numbers::pi / 2.0;
    const Eigen::Vector3d r(p.arm_length_m * std::cos(a), p.arm_length_m * std::sin(a), 0.0);
    const double f = p.kt_N_per_rad2_s2 * w[i] * w[i];
    thrust += f;
    tau += r.cross(Eigen::Vector3d(0.0, 0.0, f)) +
           Eigen::Vector3d(0.0, 0.0, p.spin[i] * p.km_Nm_per_rad2_s2 * w[i] * w[i]);
  }
  const Eigen::Quaterniond q(x[6], x[7], x[8], x[9]);
  const Eigen::Vector3d w_B = x.segment<3>(10);
  const Eigen::Vector3d I(p.Ixx_kg_m2, p.Iyy_kg_m2, p.Izz_kg_m2);
  Vec17 d = Vec17::Zero();
  d.segment<3>(0) = x.segment<3>(3);
  d.segment<3>(3) =
      q.toRotationMatrix() * Eigen::Vector3d(0.0, 0.0, thrust / p.mass_kg) - Eigen::Vector3d(0.0, 0.0, p.gravity_m_s2);
  const Eigen::Quaterniond dq = q * Eigen::Quaterniond(0.0, w_B.x(), w_B.y(), w_B.z());
  d.segment<4>(6) = 0.5 * Eigen::Vector4d(dq.w(), dq.x(), dq.y(), dq.z());
  d.segment<3>(10) = (tau - w_B.cross(I.cwiseProduct(w_B))).cwiseQuotient(I);
  if (lag) {
    for (int i = 0; i < 4; ++i) {
      const double e = cmd[i] - x[13 + i];
      d[13 + i] = e / (e > 0.0 ? p.motor.tau_up_s : p.motor.tau_down_s);
    }
  }
  return d;
}

void textbook_step(const VehicleParams& p, Vec17& x, const Vector4& cmd, double dt, int substeps) {
  const double h = dt / substeps;
  for (int s = 0; s < substeps; ++s) {
    const Vec17 k1 = textbook_derivative(p, x, cmd);
    const Vec17 k2 = textbook_derivative(p, x + 0.5 * h * k1, cmd);
    const Vec17 k3 = textbook_derivative(p, x + 0.5 * h * k2, cmd);
    const Vec17 k4 = textbook_derivative(p, x + h * k3, cmd);
    x += h / 6.0 * (k1 + 2.0 * k2 + 2.0 * k3 + k4);
    x.segment<4>(6).normalize();
  }
  if (p.motor.model == MotorModel::kIdeal) x.segment<4>(13) = cmd;
}

// Rest, climb with a roll and yaw doublet, then (from tick 400) rotors cut.
Vector4 doublet_command(const Quadrotor& m, int k) {
  const double hover = m.params().hover_omega_rad_s();
  const double s = k < 50 ? 0.5 : (k < 400 ? 1.08 : 0.0);
  const double d = k < 200 ? 40.0 * std::sin(0.05 * k) : 25.0 * std::cos(0.03 * k);
  return Vector4(hover * s + d, hover * s - 0.5 * d, hover * s - d, hover * s + 0.7 * d);
}

}  // namespace

// A neutral Environment (no wind, full efficiency, no drag or ground effect) changes no number: the
// integrator then forms the rotors' wrench at every stage, with the efficiencies, the ground-effect
// factor 1 and a zero drag, instead of once per step, and must give the same doubles through a
// take-off from the ground, manoeuvres and a drop back onto it, for both motor models, with one and
// three sub-steps.
TEST(QuadrotorStep, ANeutralEnvironmentChangesNoNumber) {
  for (const MotorModel motor : {MotorModel::kIdeal, MotorModel::kFirstOrder}) {
    for (const int substeps : {1, 3}) {
      VehicleParams params;
      params.motor.model = motor;
      const Quadrotor m{params};
      const quadcosim::model::Environment neutral;
      State a = m.initial_state({0.0, 0.0, 0.0}, 0.3, false);
      State b = a;
      for (int k = 0; k < 600; ++k) {
        const Vector4 u = doublet_command(m, k);
        const Outputs ya = m.outputs(0.01 * k, a, u), yb = m.outputs(0.01 * k, b, u, &neutral);
        ASSERT_TRUE(ya.specific_force_B == yb.specific_force_B) << "tick " << k;
        m.step(a, 0.01 * k, u, 0.01, substeps);
        m.step(b, 0.01 * k, u, 0.01, substeps, &neutral);
        ASSERT_TRUE(a.p_W == b.p_W && a.v_W == b.v_W && a.q_WB.coeffs() == b.q_WB.coeffs() && a.w_B == b.w_B &&
                    a.omega_rad_s == b.omega_rad_s)
            << "tick " << k << " substeps " << substeps << ": " << a.p_W.transpose() << " vs " << b.p_W.transpose();
      }
      EXPECT_EQ(a.p_W.z(), 0.0);                          // back on the ground
      EXPECT_GT(a.q_WB.coeffs().head<3>().norm(), 0.01);  // and it did turn on the way
    }
  }
}

// The same flight high above the ground, with and without a neutral Environment, against the
// textbook formulation above (a different association of the same sums: equal to rounding).
TEST(QuadrotorStep, FollowsAnIndependentTextbookFormulation) {
  for (const MotorModel motor : {MotorModel::kIdeal, MotorModel::kFirstOrder}) {
    for (const RotorLayout layout : {RotorLayout::kPlus, RotorLayout::kX}) {
      for (const int substeps : {1, 3}) {
        VehicleParams params;
        params.motor.model = motor;
        params.layout = layout;
        const Quadrotor m{params};
        const quadcosim::model::Environment neutral;
        State a = m.initial_state({1.0, -2.0, 50.0}, 0.3, true);
        State b = a;
        Vec17 t;
        t << a.p_W, a.v_W, a.q_WB.w(), a.q_WB.x(), a.q_WB.y(), a.q_WB.z(), a.w_B, a.omega_rad_s;
        double worst = 0.0;
        for (int k = 50; k < 400; ++k) {
          const Vector4 u = doublet_command(m, k);
          m.step(a, 0.01 * k, u, 0.01, substeps);
          m.step(b, 0.01 * k, u, 0.01, substeps, &neutral);
          textbook_step(params, t, u, 0.01, substeps);
          for (const State* x : {&a, &b}) {
            Vec17 s;
            s << x->p_W, x->v_W, x->q_WB.w(), x->q_WB.x(), x->q_WB.y(), x->q_WB.z(), x->w_B, x->omega_rad_s;
            Vec17 scale = Vec17::Ones();
            scale.segment<4>(13).setConstant(1e4);  // rotor speeds are ~1e4 rad/s
            worst = std::max(worst, (s - t).cwiseQuotient(scale).cwiseAbs().maxCoeff());
          }
        }
        EXPECT_LT(worst, 1e-9) << "motor " << static_cast<int>(motor) << " layout " << static_cast<int>(layout)
                               << " substeps " << substeps;
        EXPECT_GT((a.p_W - Eigen::Vector3d(1.0, -2.0, 50.0)).norm(), 5.0);  // it flew (open loop: off and down)
        EXPECT_GT(a.p_W.z(), 10.0);                                         // far from the ground
        EXPECT_GT(a.q_WB.coeffs().head<3>().norm(), 0.01);                  // and turned
      }
    }
  }
}
