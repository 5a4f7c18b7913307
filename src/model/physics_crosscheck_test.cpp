// Cross-checks of the plant against physics it must obey and against independent formulations
// written here: conservation of energy and angular momentum in torque-free rotation, a rotation-
// matrix integrator driven by the conserved world angular momentum, the analytic attitude of a
// constant body rate, and a 12-state Euler-angle model (the paper's eqs. (7) and (10) with the
// Z-Y-X rate kinematics) integrated with a different Runge-Kutta scheme at a 100x finer step.
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <ostream>
#include <string>
#include <vector>

#include "model/quadrotor.hpp"
#include "model/vehicle_params.hpp"

namespace {

using quadcosim::model::GyroscopicModel;
using quadcosim::model::Quadrotor;
using quadcosim::model::State;
using quadcosim::model::Vector4;
using quadcosim::model::VehicleParams;

constexpr double kDt = 0.01;  // [s] the plant tick (100 Hz)

Eigen::Matrix3d rotation_zyx(double roll, double pitch, double yaw) {
  return (Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitZ()) * Eigen::AngleAxisd(pitch, Eigen::Vector3d::UnitY()) *
          Eigen::AngleAxisd(roll, Eigen::Vector3d::UnitX()))
      .toRotationMatrix();
}

Eigen::Matrix3d skew(const Eigen::Vector3d& v) {
  Eigen::Matrix3d S;
  S << 0, -v.z(), v.y(), v.z(), 0, -v.x(), -v.y(), v.x(), 0;
  return S;
}

// Kutta's 3/8-rule fourth-order Runge-Kutta step (a different tableau from the plant's classical
// RK4).
template <class Vec, class F>
Vec rk38_step(const Vec& y, double h, F&& f) {
  const Vec k1 = f(y);
  const Vec k2 = f((y + h * k1 / 3.0).eval());
  const Vec k3 = f((y + h * (-k1 / 3.0 + k2)).eval());
  const Vec k4 = f((y + h * (k1 - k2 + k3)).eval());
  return (y + h * (k1 + 3.0 * k2 + 3.0 * k3 + k4) / 8.0).eval();
}

VehicleParams asymmetric_body() {
  VehicleParams p;
  p.Ixx_kg_m2 = 0.01;
  p.Iyy_kg_m2 = 0.02;
  p.Izz_kg_m2 = 0.03;
  return p;
}

// Starts at 1e5 m so that 100 s of free fall (49 km) never reaches the ground; rotors stopped, so
// there is no thrust and no torque and the rotation is the free Euler top.
State tumbling_state(const Eigen::Vector3d& w_B) {
  State x;
  x.p_W = {0.0, 0.0, 1e5};
  x.q_WB = Eigen::Quaterniond(rotation_zyx(0.2, -0.1, 0.5));
  x.w_B = w_B;
  return x;
}

// -------------------------------------------------------------------------------------------------
// Torque-free rotation of an asymmetric body (eq. (8) with U = 0)

struct TumbleCase {
  Eigen::Vector3d w0;
  const char* name;
};

void PrintTo(const TumbleCase& c, std::ostream* os) { *os << c.name; }

class TorqueFree : public ::testing::TestWithParam<TumbleCase> {};

TEST_P(TorqueFree, ConservesEnergyAndWorldAngularMomentum) {
  const VehicleParams p = asymmetric_body();
  const Eigen::Vector3d I(p.Ixx_kg_m2, p.Iyy_kg_m2, p.Izz_kg_m2);
  const Quadrotor quad(p);
  State x = tumbling_state(GetParam().w0);
  const Vector4 off = Vector4::Zero();

  auto energy = [&](const State& s) { return 0.5 * s.w_B.dot(I.cwiseProduct(s.w_B)); };
  auto momentum_W = [&](const State& s) { return (s.q_WB * I.cwiseProduct(s.w_B)).eval(); };
  const double T0 = energy(x);
  const Eigen::Vector3d L0 = momentum_W(x);

  // 10 RK4 substeps per 10 ms tick (h = 1 ms). Measured drift over 100 s: with 1 substep 3e-10
  // (generic) and 4e-9 (near the intermediate axis, |w| = 2 rad/s) in momentum, which misses 1e-9;
  // with 2 substeps 3e-10; with 10 substeps about 1e-13, near rounding, so 1e-9 has a wide margin.
  constexpr int kSubsteps = 10;
  double max_dT = 0.0, max_dL = 0.0;
  int flips = 0;
  double wy_prev = x.w_B.y();
  for (int k = 0; k < 10000; ++k) {  // 100 s
    quad.step(x, k * kDt, off, kDt, kSubsteps);
    max_dT = std::max(max_dT, std::abs(energy(x) - T0) / T0);
    max_dL = std::max(max_dL, (momentum_W(x) - L0).norm() / L0.norm());
    if (x.w_B.y() * wy_prev < 0.0) ++flips;
    wy_prev = x.w_B.y();
  }
  EXPECT_LT(max_dT, 1e-9) << GetParam().name;
  EXPECT_LT(max_dL, 1e-9) << GetParam().name;
  EXPECT_GT(x.p_W.z(), 0.0);  // never touched the ground
  // Both starts are near the intermediate (y) axis, which is unstable: the body must tumble, i.e.
  // the y rate reverses sign (the Dzhanibekov flip), at least a few times in 100 s.
  EXPECT_GE(flips, 2) << GetParam().name;
}

INSTANTIATE_TEST_SUITE_P(Cases, TorqueFree,
                         ::testing::Values(TumbleCase{{0.3, 1.0, 0.2}, "w0 (0.3, 1.0, 0.2)"},
                                           TumbleCase{{1e-3, 2.0, 1e-3}, "w0 close to the intermediate axis"}),
                         [](const auto& info) {
                           return info.index == 0 ? std::string("Generic") : std::string("NearIntermediateAxis");
                         });

// Independent formulation: with no torque the world angular momentum L_W is a constant, so the
// whole motion is R' = [w_W]x R with w_W = R I^-1 R^T L_W. Integrate that with the 3/8 rule at h =
// 0.25 ms and compare attitude and body rates with the plant over 20 s.
TEST(TorqueFreeCrossCheck, MatchesConstantMomentumRotationMatrixIntegrator) {
  const VehicleParams p = asymmetric_body();
  const Eigen::Vector3d I(p.Ixx_kg_m2, p.Iyy_kg_m2, p.Izz_kg_m2);
  const Quadrotor quad(p);
  State x = tumbling_state({0.3, 1.0, 0.2});
  const Eigen::Matrix3d R0 = x.q_WB.toRotationMatrix();
  const Eigen::Vector3d L_W = R0 * I.cwiseProduct(x.w_B);

  using Vec9 = Eigen::Matrix<double, 9, 1>;
  auto f = [&](const Vec9& y) -> Vec9 {
    const Eigen::Map<const Eigen::Matrix3d> R(y.data());
    const Eigen::Vector3d w_W = R * (R.transpose() * L_W).cwiseQuotient(I);
    Vec9 out;
    Eigen::Map<Eigen::Matrix3d>(out.data()) = skew(w_W) * R;
    return out;
  };
  Vec9 y;
  Eigen::Map<Eigen::Matrix3d>(y.data()) = R0;
  constexpr int kRefPerTick = 40;  // h_ref = 0.25 ms
  double max_dR = 0.0, max_dw = 0.0;
  for (int k = 0; k < 2000; ++k) {  // 20 s
    quad.step(x, k * kDt, Vector4::Zero(), kDt, 10);
    for (int j = 0; j < kRefPerTick; ++j) y = rk38_step(y, kDt / kRefPerTick, f);
    const Eigen::Map<const Eigen::Matrix3d> R_ref(y.data());
    const Eigen::Vector3d w_ref = (R_ref.transpose() * L_W).cwiseQuotient(I);
    max_dR = std::max(max_dR, (x.q_WB.toRotationMatrix() - R_ref).cwiseAbs().maxCoeff());
    max_dw = std::max(max_dw, (x.w_B - w_ref).norm());
  }
  const Eigen::Map<const Eigen::Matrix3d> R_end(y.data());
  // The reference stays a rotation to rounding, so it is a fair yardstick.
  EXPECT_LT((R_end.transpose() * R_end - Eigen::Matrix3d::Identity()).norm(), 1e-10);
  // Measured ~2e-13 for both (the plant at 10 substeps and the reference are each near rounding).
  EXPECT_LT(max_dR, 1e-10);
  EXPECT_LT(max_dw, 1e-10);
}

TEST(TorqueFreeRotation, QuaternionStaysUnitOverLongTumble) {
  // The plant's default setting (one RK4 step per tick) and a vigorous tumble, 200 s.
  const VehicleParams p = asymmetric_body();
  const Quadrotor quad(p);
  State x = tumbling_state({2.0, -3.0, 1.5});
  x.p_W.z() = 1e6;
  double worst = 0.0;
  for (int k = 0; k < 20000; ++k) {
    quad.step(x, k * kDt, Vector4::Zero(), kDt, 1);
    worst = std::max(worst, std::abs(x.q_WB.norm() - 1.0));
  }
  EXPECT_LT(worst, 1e-12);
  EXPECT_TRUE(x.w_B.allFinite());
}

TEST(TorqueFreeRotation, SimplifiedGyroscopicModelKeepsBodyRateAndSpinsAboutIt) {
  VehicleParams p = asymmetric_body();
  p.gyroscopic = GyroscopicModel::kSimplified;  // eq. (11): I dw = tau = 0
  const Quadrotor quad(p);
  const Eigen::Vector3d w0(0.3, 1.0, 0.2);
  State x = tumbling_state(w0);
  const Eigen::Quaterniond q0 = x.q_WB;
  const double rate = w0.norm();
  double worst = 0.0;
  for (int k = 1; k <= 10000; ++k) {  // 100 s, one substep (the plant default)
    quad.step(x, (k - 1) * kDt, Vector4::Zero(), kDt, 1);
    ASSERT_EQ(x.w_B, w0);
    // Constant body rate: q(t) = q0 (x) exp(t w / 2), a steady spin about the fixed axis w0.
    const Eigen::Quaterniond q_exact = q0 * Eigen::Quaterniond(Eigen::AngleAxisd(rate * k * kDt, w0 / rate));
    worst = std::max(worst, x.q_WB.angularDistance(q_exact));
  }
  // RK4 on q' = 1/2 q (0, w): phase error per step (h |w| / 2)^5 / 120 * 2 = 6e-14 rad, 1e4 steps:
  // 6e-10 rad, plus rounding.
  EXPECT_LT(worst, 2e-9);
}

// -------------------------------------------------------------------------------------------------
// Full 6-DOF against an independent Euler-angle model

// The paper's model in its own coordinates: y = (x, y, z, vx, vy, vz, phi, theta, psi, p, q, r).
// Translation eq. (7), rotation eq. (10), Z-Y-X Euler-angle kinematics, eq. (4) for U.
using Vec12 = Eigen::Matrix<double, 12, 1>;

Vec12 euler_model(const Vec12& s, const VehicleParams& v, const Vector4& w) {
  const double w1 = w[0] * w[0], w2 = w[1] * w[1], w3 = w[2] * w[2], w4 = w[3] * w[3];
  const double kt = v.kt_N_per_rad2_s2, km = v.km_Nm_per_rad2_s2, L = v.arm_length_m;
  const double U1 = kt * (w1 + w2 + w3 + w4), U2 = L * kt * (w4 - w2), U3 = L * kt * (w3 - w1),
               U4 = km * (w1 - w2 + w3 - w4);
  const double m = v.mass_kg, g = v.gravity_m_s2;
  const double Ixx = v.Ixx_kg_m2, Iyy = v.Iyy_kg_m2, Izz = v.Izz_kg_m2;
  const double phi = s[6], th = s[7], psi = s[8], P = s[9], Q = s[10], R = s[11];
  const double cf = std::cos(phi), sf = std::sin(phi), ct = std::cos(th), st = std::sin(th), tt = std::tan(th),
               cp = std::cos(psi), sp = std::sin(psi);
  Vec12 d;
  d.segment<3>(0) = s.segment<3>(3);
  d[3] = U1 / m * (cp * st * cf + sp * sf);
  d[4] = U1 / m * (sp * st * cf - cp * sf);
  d[5] = U1 / m * (ct * cf) - g;
  d[6] = P + (Q * sf + R * cf) * tt;
  d[7] = Q * cf - R * sf;
  d[8] = (Q * sf + R * cf) / ct;
  d[9] = (U2 + (Iyy - Izz) * Q * R) / Ixx;
  d[10] = (U3 + (Izz - Ixx) * P * R) / Iyy;
  d[11] = (U4 + (Ixx - Iyy) * P * Q) / Izz;
  return d;
}

struct Errors {
  double p = 0, v = 0, att = 0, w = 0;
  double max() const { return std::max({p, v, att, w}); }
};

// Flies the plant with `substeps` per tick and the reference at 100 steps per tick for 2 s and
// returns the largest deviation seen at any tick.
Errors fly_against_reference(int substeps) {
  const VehicleParams v;  // the paper's vehicle, full gyroscopic model
  const Quadrotor quad(v);
  const double wh = v.hover_omega_rad_s();
  // Slightly uneven rotors: roll, pitch and yaw torques at once and a little extra thrust.
  const Vector4 w = wh * Vector4(1.0006, 0.9997, 0.9998, 1.0004);
  const double phi0 = 0.1, th0 = -0.2, psi0 = 0.3;
  const Eigen::Vector3d p0(1.0, 2.0, 30.0), v0(0.5, -0.3, 0.2), w0(0.5, -0.4, 4.0);

  State x;
  x.p_W = p0;
  x.v_W = v0;
  x.q_WB = Eigen::Quaterniond(rotation_zyx(phi0, th0, psi0));
  x.w_B = w0;
  x.omega_rad_s = w;

  Vec12 s;
  s << p0, v0, phi0, th0, psi0, w0;
  auto f = [&](const Vec12& y) { return euler_model(y, v, w); };
  constexpr int kRefPerTick = 100;  // h_ref = 0.1 ms

  Errors e;
  for (int k = 0; k < 200; ++k) {
    quad.step(x, k * kDt, w, kDt, substeps);
    for (int j = 0; j < kRefPerTick; ++j) s = rk38_step(s, kDt / kRefPerTick, f);
    EXPECT_LT(std::abs(s[7]), 1.2);  // the reference stays clear of its gimbal lock
    e.p = std::max(e.p, (x.p_W - s.segment<3>(0)).norm());
    e.v = std::max(e.v, (x.v_W - s.segment<3>(3)).norm());
    e.att = std::max(e.att,
                     Eigen::AngleAxisd(x.q_WB.toRotationMatrix().transpose() * rotation_zyx(s[6], s[7], s[8])).angle());
    e.w = std::max(e.w, (x.w_B - s.segment<3>(9)).norm());
  }
  EXPECT_GT(x.p_W.z(), 0.0);  // stayed airborne: no ground contact in the comparison
  return e;
}

TEST(EulerAngleCrossCheck, PlantMatchesEq7And10WithEulerKinematics) {
  // With w0 = (0.5, -0.4, 4) the roll and pitch rates precess at
  // Omega = r sqrt((Izz - Iyy)(Izz - Ixx) / (Ixx Iyy)) ~ 10 rad/s. RK4 on a rotation at Omega makes
  // a phase error of (h Omega)^5 / 120 per step, so after N steps the rates are off by at most
  // about N (h Omega)^5 / 120 |(p, q)|; the reference's own error (3/8 rule, h = 0.1 ms) is ~1e8
  // smaller.
  const VehicleParams v;
  const double Omega =
      4.0 * std::sqrt((v.Izz_kg_m2 - v.Iyy_kg_m2) * (v.Izz_kg_m2 - v.Ixx_kg_m2) / (v.Ixx_kg_m2 * v.Iyy_kg_m2));
  const double pq = std::hypot(0.5, 0.4);
  auto bound = [&](int substeps) {
    const double h = kDt / substeps;
    return 2.0 * (200 * substeps) * std::pow(h * Omega, 5) / 120.0 * pq;  // factor 2 margin
  };
  const Errors e1 = fly_against_reference(1);
  const Errors e2 = fly_against_reference(2);
  const Errors e8 = fly_against_reference(8);
  EXPECT_LT(e1.max(), bound(1));  // ~2.2e-5
  EXPECT_LT(e2.max(), bound(2));
  EXPECT_LT(e8.max(), bound(8));  // ~5e-9
  // Position, velocity and attitude errors are far smaller than the rate error at the plant's step.
  EXPECT_LT(std::max({e1.p, e1.v, e1.att}), 1e-6);
  // Halving the step divides the error by 2^4 = 16 for a fourth-order method, which also shows the
  // remaining difference is truncation error, not a difference between the two models.
  const double ratio = e1.max() / e2.max();
  EXPECT_GT(ratio, 14.0);
  EXPECT_LT(ratio, 18.0);
  RecordProperty("error_substeps_1", std::to_string(e1.max()));
  RecordProperty("error_substeps_8", std::to_string(e8.max()));
}

// -------------------------------------------------------------------------------------------------
// A body whose axes are not principal axes (products of inertia): J = R_BP D R_BP^T

// A tensor with products of inertia: the principal moments D turned by R_BP (principal axes P ->
// body B).
VehicleParams tilted_tensor_body(const Eigen::Matrix3d& R_BP, const Eigen::Vector3d& D) {
  const Eigen::Matrix3d J = R_BP * D.asDiagonal() * R_BP.transpose();
  VehicleParams p;
  p.Ixx_kg_m2 = J(0, 0);
  p.Iyy_kg_m2 = J(1, 1);
  p.Izz_kg_m2 = J(2, 2);
  p.Ixy_kg_m2 = J(0, 1);
  p.Ixz_kg_m2 = J(0, 2);
  p.Iyz_kg_m2 = J(1, 2);
  return p;
}

// Torque-free rotation with the whole tensor: kinetic energy 1/2 w^T J w and the world angular
// momentum R_WB J w are constants of the motion (as for the diagonal body above).
TEST(ProductsOfInertia, TorqueFreeRotationConservesEnergyAndWorldAngularMomentum) {
  const VehicleParams p = tilted_tensor_body(rotation_zyx(0.4, -0.7, 1.1), {0.01, 0.02, 0.03});
  ASSERT_FALSE(p.principal_axes());
  ASSERT_EQ(quadcosim::model::validate(p), "");
  const Eigen::Matrix3d J = p.inertia_tensor();
  const Quadrotor quad(p);
  State x = tumbling_state({0.3, 1.0, 0.2});
  auto energy = [&](const State& s) { return 0.5 * s.w_B.dot(J * s.w_B); };
  auto momentum_W = [&](const State& s) { return (s.q_WB * (J * s.w_B)).eval(); };
  const double T0 = energy(x);
  const Eigen::Vector3d L0 = momentum_W(x);
  double max_dT = 0.0, max_dL = 0.0;
  for (int k = 0; k < 10000; ++k) {  // 100 s, 10 substeps a tick as above
    quad.step(x, k * kDt, Vector4::Zero(), kDt, 10);
    max_dT = std::max(max_dT, std::abs(energy(x) - T0) / T0);
    max_dL = std::max(max_dL, (momentum_W(x) - L0).norm() / L0.norm());
  }
  EXPECT_LT(max_dT, 1e-9);
  EXPECT_LT(max_dL, 1e-9);
}

// Independent formulation: the same body described in its principal axes P has the diagonal tensor D
// (the diagonal path, checked above against closed forms): w_P = R_BP^T w_B, q_WP = q_WB q_BP. Both
// runs must describe one motion: w_B = R_BP w_P and q_WB = q_WP q_BP^-1 over 20 s of tumbling.
TEST(ProductsOfInertia, MatchesTheSameBodyIntegratedInItsPrincipalAxes) {
  const Eigen::Matrix3d R_BP = rotation_zyx(0.4, -0.7, 1.1);
  const Eigen::Vector3d D(0.01, 0.02, 0.03);
  VehicleParams principal;
  principal.Ixx_kg_m2 = D.x();
  principal.Iyy_kg_m2 = D.y();
  principal.Izz_kg_m2 = D.z();
  const Quadrotor tilted(tilted_tensor_body(R_BP, D)), aligned(principal);
  State b = tumbling_state({0.3, 1.0, 0.2});
  State a = b;
  const Eigen::Quaterniond q_BP(R_BP);
  a.q_WB = b.q_WB * q_BP;
  a.w_B = R_BP.transpose() * b.w_B;
  double max_w = 0.0, max_att = 0.0;
  for (int k = 0; k < 2000; ++k) {  // 20 s at the plant's step, one substep
    tilted.step(b, k * kDt, Vector4::Zero(), kDt, 1);
    aligned.step(a, k * kDt, Vector4::Zero(), kDt, 1);
    max_w = std::max(max_w, (R_BP * a.w_B - b.w_B).norm());
    max_att = std::max(max_att, (a.q_WB * q_BP.conjugate()).angularDistance(b.q_WB));
  }
  // RK4 commutes with a constant linear change of variables, so the two differ by rounding only
  // (measured ~1e-14); 1e-10 leaves room and still catches a wrong sign or a transposed tensor.
  EXPECT_LT(max_w, 1e-10);
  EXPECT_LT(max_att, 1e-10);
  std::printf("whole tensor vs principal axes over 20 s: rates differ by %.3g rad/s, attitude by %.3g rad\n", max_w,
              max_att);
}

TEST(ProductsOfInertia, ATensorThatIsNotPositiveDefiniteIsRefusedByName) {
  VehicleParams p;  // Ixx 0.0149, Iyy 0.0153: a product above sqrt(Ixx Iyy) leaves no body
  p.Ixy_kg_m2 = 0.016;
  const std::string err = quadcosim::model::validate(p);
  EXPECT_NE(err.find("Ixy_kg_m2"), std::string::npos) << err;
  EXPECT_NE(err.find("positive definite"), std::string::npos) << err;
  p.Ixy_kg_m2 = 0.001;  // a small product is a body
  EXPECT_EQ(quadcosim::model::validate(p), "");
}

}  // namespace
