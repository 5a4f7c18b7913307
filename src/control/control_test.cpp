// Tests of allocation, altitude PD (eq. (13)), position PID, the flight controller step (Algorithm 1)
// and the parameter table. Expected numbers are computed here from the paper's equations written out
// by hand (eq. (4) mixer, eq. (7) small-angle translation, eq. (13) thrust, hover speed), never by
// feeding the code's own output back as the expectation.
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <Eigen/LU>
#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <numbers>
#include <stdexcept>
#include <string>
#include <variant>
#include <vector>

#include "control/allocation.hpp"
#include "control/altitude_pd.hpp"
#include "control/care.hpp"
#include "control/controller.hpp"
#include "control/controller_config.hpp"
#include "control/parameters.hpp"
#include "control/position_pid.hpp"
#include "controllers/paper/paper_controller.hpp"
#include "controllers/registry.hpp"
#include "model/mixer.hpp"
#include "model/quadrotor.hpp"
#include "model/vehicle_params.hpp"

namespace {

using namespace quadcosim::control;
using quadcosim::controllers::PaperController;
using quadcosim::controllers::PaperParams;
using quadcosim::model::VehicleParams;

constexpr double kPi = std::numbers::pi;
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
constexpr double kInf = std::numeric_limits<double>::infinity();

// Table 1 of the paper, typed in again.
constexpr double kMass = 1.96, kG = 9.81, kL = 0.59, kKt = 2.06e-7, kKm = 1.01e-10;

// Eq. (4) for the '+' layout, written out by hand.
Eigen::Matrix4d eq4(double kt = kKt, double km = kKm, double L = kL) {
  Eigen::Matrix4d M;
  M << kt, kt, kt, kt,        //
      0, -L * kt, 0, L * kt,  //
      -L * kt, 0, L * kt, 0,  //
      km, -km, km, -km;
  return M;
}

Eigen::Vector4d squared(const Eigen::Vector4d& w) { return w.cwiseProduct(w); }

// ---------------------------------------------------------------------------------------------------
// Allocation (Algorithm 1, lines 16-20).

TEST(Allocation, ModelMixerIsEq4) {
  // The controller inverts model::mixer_matrix; it must be the eq. (4) matrix used below.
  const Eigen::Matrix4d M = quadcosim::model::mixer_matrix(VehicleParams{});
  EXPECT_LE((M - eq4()).norm(), 1e-15 * eq4().norm());
}

TEST(Allocation, RoundTripThroughTheMixer) {
  const Eigen::Matrix4d M = eq4();
  const Eigen::Matrix4d Minv = M.inverse();
  const double wmin = 0.0, wmax = 12000.0;
  std::vector<Eigen::Vector4d> speeds = {
      {4830.6, 4830.6, 4830.6, 4830.6}, {4000, 5200, 4700, 6100}, {100, 11900, 3000, 9000}};
  // Plus a deterministic spread over the feasible range.
  for (int k = 0; k < 50; ++k) {
    Eigen::Vector4d w;
    for (int i = 0; i < 4; ++i) w[i] = 500.0 + std::fmod(1234.5 * (k + 1) * (i + 3) + 77.0 * k * k, 11000.0);
    speeds.push_back(w);
  }
  for (const auto& w : speeds) {
    SCOPED_TRACE(testing::Message() << "w = " << w.transpose());
    const Eigen::Vector4d U = M * squared(w);
    const Allocation a = allocate(Minv, U, wmin, wmax);
    for (int i = 0; i < 4; ++i) {
      // Inversion of a matrix whose rows span 3 decades: 1e-9 relative covers its condition number.
      EXPECT_NEAR(a.omega_rad_s[i], w[i], 1e-9 * wmax);
      EXPECT_FALSE(a.saturated[i]) << "rotor " << i + 1;
    }
    // U = M w^2 reproduced, each row against the size of its terms.
    const Eigen::Vector4d U_back = M * squared(a.omega_rad_s);
    const Eigen::Vector4d row_scale = M.cwiseAbs() * squared(w);
    for (int r = 0; r < 4; ++r) EXPECT_NEAR(U_back[r], U[r], 1e-9 * row_scale[r]) << "row " << r;
  }
}

TEST(Allocation, ClampsAtOmegaMaxAndMinFlaggingExactlyTheClampedRotors) {
  const Eigen::Matrix4d M = eq4();
  const double wmin = 1000.0, wmax = 8000.0;
  // Demanded w^2: rotor 1 above the top, rotor 3 below the bottom, rotors 2 and 4 inside.
  const Eigen::Vector4d demand(9000.0 * 9000.0, 5000.0 * 5000.0, 500.0 * 500.0, 3000.0 * 3000.0);
  const Allocation a = allocate(M.inverse(), M * demand, wmin, wmax);
  EXPECT_EQ(a.omega_rad_s[0], wmax);
  EXPECT_NEAR(a.omega_rad_s[1], 5000.0, 1e-9 * wmax);
  EXPECT_EQ(a.omega_rad_s[2], wmin);
  EXPECT_NEAR(a.omega_rad_s[3], 3000.0, 1e-9 * wmax);
  EXPECT_TRUE(a.saturated[0]);
  EXPECT_FALSE(a.saturated[1]);
  EXPECT_TRUE(a.saturated[2]);
  EXPECT_FALSE(a.saturated[3]);

  // The other pair.
  const Eigen::Vector4d demand2(4000.0 * 4000.0, 100.0 * 100.0, 7000.0 * 7000.0, 20000.0 * 20000.0);
  const Allocation b = allocate(M.inverse(), M * demand2, wmin, wmax);
  EXPECT_NEAR(b.omega_rad_s[0], 4000.0, 1e-9 * wmax);
  EXPECT_EQ(b.omega_rad_s[1], wmin);
  EXPECT_NEAR(b.omega_rad_s[2], 7000.0, 1e-9 * wmax);
  EXPECT_EQ(b.omega_rad_s[3], wmax);
  EXPECT_EQ(b.saturated, (std::array<bool, 4>{false, true, false, true}));
}

TEST(Allocation, NegativeSquaredSpeedsGiveOmegaMin) {
  const Eigen::Matrix4d M = eq4();
  // Default omega_min is 0: sqrt(max(0, w^2)) of Algorithm 1, line 19.
  EXPECT_EQ(VehicleParams{}.motor.omega_min_rad_s, 0.0);
  const Eigen::Vector4d demand(-1e6, 4000.0 * 4000.0, -5e5, 4500.0 * 4500.0);
  const Allocation a = allocate(M.inverse(), M * demand, 0.0, 12000.0);
  EXPECT_EQ(a.omega_rad_s[0], 0.0);
  EXPECT_NEAR(a.omega_rad_s[1], 4000.0, 1e-6);
  EXPECT_EQ(a.omega_rad_s[2], 0.0);
  EXPECT_NEAR(a.omega_rad_s[3], 4500.0, 1e-6);
  EXPECT_EQ(a.saturated, (std::array<bool, 4>{true, false, true, false}));

  // With a positive floor the negative demands go to it.
  const Allocation b = allocate(M.inverse(), M * demand, 600.0, 12000.0);
  EXPECT_EQ(b.omega_rad_s[0], 600.0);
  EXPECT_EQ(b.omega_rad_s[2], 600.0);

  // A large negative collective thrust: every rotor at the floor.
  const Allocation c = allocate(M.inverse(), Eigen::Vector4d(-50.0, 0, 0, 0), 0.0, 12000.0);
  EXPECT_EQ(c.omega_rad_s, Eigen::Vector4d::Zero());
  EXPECT_EQ(c.saturated, (std::array<bool, 4>{true, true, true, true}));
}

TEST(Allocation, NonFiniteDemandGivesFiniteBoundedOutput) {
  const Eigen::Matrix4d Minv = eq4().inverse();
  const double wmin = 200.0, wmax = 9000.0;
  for (const Eigen::Vector4d& U :
       {Eigen::Vector4d(kNaN, 0, 0, 0), Eigen::Vector4d(19.0, kNaN, 0, 0), Eigen::Vector4d(19.0, 0, 0, kNaN),
        Eigen::Vector4d(kInf, 0, 0, 0), Eigen::Vector4d(19.0, -kInf, 0, 0), Eigen::Vector4d(kNaN, kNaN, kNaN, kNaN)}) {
    SCOPED_TRACE(testing::Message() << "U = " << U.transpose());
    const Allocation a = allocate(Minv, U, wmin, wmax);
    EXPECT_TRUE(a.omega_rad_s.allFinite());
    for (int i = 0; i < 4; ++i) {
      EXPECT_GE(a.omega_rad_s[i], wmin);
      EXPECT_LE(a.omega_rad_s[i], wmax);
    }
    // A NaN in U1 reaches every rotor; such a rotor is reported saturated.
    if (std::isnan(U[0])) {
      EXPECT_EQ(a.saturated, (std::array<bool, 4>{true, true, true, true}));
      EXPECT_EQ(a.omega_rad_s, Eigen::Vector4d::Constant(wmin));
    }
  }
}

// ---------------------------------------------------------------------------------------------------
// Altitude PD, eq. (13).

TEST(CollectiveThrust, Eq13AtSeveralTilts) {
  const AltitudeGains g;  // kp 4, kd 2.7, floor 0.5
  struct Case {
    double z_des, z, vz, roll, pitch;
  };
  for (const Case c : {Case{0, 0, 0, 0, 0}, Case{10, 9.5, 0.3, 0.2, -0.15}, Case{10, 0, 0, 0, 0},
                       Case{2, 3, -1, -0.5, 0.4}, Case{5, 5, 0, 0.7, 0.0}, Case{1, 1.2, 0.1, 0.0, -0.9}}) {
    SCOPED_TRACE(testing::Message() << c.z_des << " " << c.z << " " << c.vz << " " << c.roll << " " << c.pitch);
    const double tilt = std::cos(c.roll) * std::cos(c.pitch);
    ASSERT_GT(tilt, 0.5) << "test case meant to be above the floor";
    const double expected = (kMass * kG + 4.0 * (c.z_des - c.z) - 2.7 * c.vz) / tilt;
    const double got = collective_thrust(g, kMass, kG, c.z_des, c.z, c.vz, c.roll, c.pitch);
    EXPECT_NEAR(got, expected, 1e-13 * expected);
  }
  // Level hover is exactly m g.
  EXPECT_EQ(collective_thrust(g, kMass, kG, 3, 3, 0, 0, 0), kMass * kG);
}

TEST(CollectiveThrust, TiltFloorKeepsItFiniteAndBounded) {
  AltitudeGains g;
  const double u = kMass * kG + g.kp * 1.0;  // 1 m below the setpoint, at rest
  // At 75 deg roll, 90 deg pitch and upside down the compensation stops at 1/min_cos_tilt.
  for (double roll : {1.3, kPi / 2, kPi, -kPi, 2.5}) {
    EXPECT_DOUBLE_EQ(collective_thrust(g, kMass, kG, 1, 0, 0, roll, 0), u / g.min_cos_tilt) << roll;
    EXPECT_DOUBLE_EQ(collective_thrust(g, kMass, kG, 1, 0, 0, 0, roll), u / g.min_cos_tilt) << roll;
  }
  // Sweep every attitude: finite, non-negative, never above u / floor, and equal to eq. (13) with the
  // floor written out here.
  for (double floor : {0.05, 0.5, 1.0}) {
    g.min_cos_tilt = floor;
    for (double roll = -kPi; roll <= kPi; roll += 0.05) {
      for (double pitch = -kPi / 2; pitch <= kPi / 2; pitch += 0.05) {
        const double T = collective_thrust(g, kMass, kG, 1, 0, 0, roll, pitch);
        ASSERT_TRUE(std::isfinite(T));
        ASSERT_GE(T, 0.0);
        ASSERT_LE(T, u / floor * (1 + 1e-15));
        const double c = std::cos(roll) * std::cos(pitch);
        ASSERT_NEAR(T, u / (c > floor ? c : floor), 1e-13 * u / floor) << roll << " " << pitch;
      }
    }
  }
}

TEST(CollectiveThrust, NeverNegative) {
  const AltitudeGains g;
  // 20 m above the setpoint: m g + 4 (-20) < 0 -> 0, not a downward thrust rotors cannot make.
  EXPECT_EQ(collective_thrust(g, kMass, kG, 0, 20, 0, 0, 0), 0.0);
  // Climbing fast.
  EXPECT_EQ(collective_thrust(g, kMass, kG, 0, 0, 10, 0.3, 0.2), 0.0);
  // Upside down and high.
  EXPECT_EQ(collective_thrust(g, kMass, kG, 0, 50, 0, kPi, 0), 0.0);
  // Just positive stays positive.
  const double z = (kMass * kG - 0.1) / 4.0;  // leaves 0.1 N
  EXPECT_NEAR(collective_thrust(g, kMass, kG, 0, z, 0, 0, 0), 0.1, 1e-12);
}

// ---------------------------------------------------------------------------------------------------
// Position PID.

// Small-angle eq. (7) with U1 = m g: x'' = g (cos psi theta + sin psi phi), y'' = g (sin psi theta -
// cos psi phi). The acceleration the commanded tilt produces, computed forward here.
Eigen::Vector2d small_angle_accel(double roll, double pitch, double yaw, double g) {
  return {g * (std::cos(yaw) * pitch + std::sin(yaw) * roll), g * (std::sin(yaw) * pitch - std::cos(yaw) * roll)};
}

// Horizontal direction of the thrust axis z_B in the world for R_WB = Rz(yaw) Ry(pitch) Rx(roll).
Eigen::Vector2d thrust_direction(double roll, double pitch, double yaw) {
  const Eigen::Matrix3d R =
      (Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitZ()) * Eigen::AngleAxisd(pitch, Eigen::Vector3d::UnitY()) *
       Eigen::AngleAxisd(roll, Eigen::Vector3d::UnitX()))
          .toRotationMatrix();
  return R.col(2).head<2>();
}

// Brisk gains (those of scenarios/examples/position_step.yaml, with a larger K_i so the integral
// term shows), set explicitly so the tests do not depend on the tuned defaults.
PositionGains brisk_gains() {
  PositionGains k;
  k.kp = 0.8;
  k.ki = 0.05;
  k.kd = 1.4;
  k.integral_limit = 2.0;
  k.max_tilt_rad = 0.35;
  return k;
}

TEST(PositionPid, SignsAtYawZeroAndHalfPi) {
  const PositionGains k = brisk_gains();
  const double dt = 0.02;
  // +x error at yaw 0: positive pitch (nose down tilts the thrust towards +x), no roll.
  {
    PositionPidState s;
    const TiltSetpoint t = position_pid(k, s, {1, 0}, {0, 0}, {0, 0}, 0.0, kG, dt);
    EXPECT_GT(t.pitch_rad, 0.0);
    EXPECT_EQ(t.roll_rad, 0.0);
    EXPECT_GT(thrust_direction(t.roll_rad, t.pitch_rad, 0.0).x(), 0.0);
  }
  // +x error at yaw pi/2 (nose along +y): eq. (7) gives x'' = g phi, so positive roll, ~no pitch.
  {
    PositionPidState s;
    const TiltSetpoint t = position_pid(k, s, {1, 0}, {0, 0}, {0, 0}, kPi / 2, kG, dt);
    EXPECT_GT(t.roll_rad, 0.0);
    EXPECT_NEAR(t.pitch_rad, 0.0, 1e-15);
    EXPECT_GT(thrust_direction(t.roll_rad, t.pitch_rad, kPi / 2).x(), 0.0);
  }
  // +y error at yaw 0: y'' = -g phi, so negative roll (left side down, thrust tilted towards +y).
  {
    PositionPidState s;
    const TiltSetpoint t = position_pid(k, s, {0, 1}, {0, 0}, {0, 0}, 0.0, kG, dt);
    EXPECT_LT(t.roll_rad, 0.0);
    EXPECT_EQ(t.pitch_rad, 0.0);
    EXPECT_GT(thrust_direction(t.roll_rad, t.pitch_rad, 0.0).y(), 0.0);
  }
  // Velocity damps: moving at +x with no error asks for negative pitch at yaw 0.
  {
    PositionPidState s;
    const TiltSetpoint t = position_pid(k, s, {0, 0}, {0, 0}, {1, 0}, 0.0, kG, dt);
    EXPECT_LT(t.pitch_rad, 0.0);
  }
}

TEST(PositionPid, TiltProducesTheDesiredAccelerationAtAnyHeading) {
  const PositionGains k = brisk_gains();
  const double dt = 0.02;
  for (double yaw : {0.0, 0.4, kPi / 2, 2.0, kPi, -0.8, -kPi / 2, -2.9}) {
    for (const Eigen::Vector2d& e : {Eigen::Vector2d(0.3, 0), Eigen::Vector2d(0, -0.2), Eigen::Vector2d(0.25, 0.1)}) {
      for (const Eigen::Vector2d& v : {Eigen::Vector2d(0, 0), Eigen::Vector2d(0.1, -0.05)}) {
        SCOPED_TRACE(testing::Message() << "yaw " << yaw << " e " << e.transpose() << " v " << v.transpose());
        PositionPidState s;
        const Eigen::Vector2d p(3.0, -1.0);
        const TiltSetpoint t = position_pid(k, s, p + e, p, v, yaw, kG, dt);
        ASSERT_FALSE(t.saturated);
        // a_des = kp e + ki (e dt) - kd v after one step from a zero integral.
        const Eigen::Vector2d a_des = k.kp * e + k.ki * (e * dt) - k.kd * v;
        const Eigen::Vector2d a = small_angle_accel(t.roll_rad, t.pitch_rad, yaw, kG);
        EXPECT_NEAR(a.x(), a_des.x(), 1e-12);
        EXPECT_NEAR(a.y(), a_des.y(), 1e-12);
        // The full rotation tilts the thrust axis towards a_des (small angles: within 2 degrees).
        const Eigen::Vector2d d = thrust_direction(t.roll_rad, t.pitch_rad, yaw);
        const double angle = std::atan2(d.x() * a_des.y() - d.y() * a_des.x(), d.dot(a_des));
        EXPECT_LT(std::abs(angle), 0.035);
      }
    }
  }
}

TEST(PositionPid, TiltLimitRespected) {
  const PositionGains k = brisk_gains();  // max tilt 0.35
  for (double yaw : {0.0, 0.7, -2.0, kPi}) {
    for (const Eigen::Vector2d& e : {Eigen::Vector2d(100, 0), Eigen::Vector2d(-50, 80), Eigen::Vector2d(0, -1e4)}) {
      PositionPidState s;
      const TiltSetpoint t = position_pid(k, s, e, {0, 0}, {0, 0}, yaw, kG, 0.02);
      EXPECT_TRUE(t.saturated);
      EXPECT_LE(std::abs(t.roll_rad), k.max_tilt_rad);
      EXPECT_LE(std::abs(t.pitch_rad), k.max_tilt_rad);
      EXPECT_TRUE(std::abs(t.roll_rad) == k.max_tilt_rad || std::abs(t.pitch_rad) == k.max_tilt_rad);
    }
  }
  // Large velocity alone also saturates, towards braking.
  PositionPidState s;
  const TiltSetpoint t = position_pid(k, s, {0, 0}, {0, 0}, {30, 0}, 0.0, kG, 0.02);
  EXPECT_TRUE(t.saturated);
  EXPECT_EQ(t.pitch_rad, -k.max_tilt_rad);
}

TEST(PositionPid, IntegratesErrorTimesDtExactlyWhenUnsaturatedAndStopsAtTheLimit) {
  PositionGains k;
  k.kp = 0.001;  // keeps the output far from the tilt limit
  k.ki = 0.05;
  k.kd = 0.0;
  const double dt = 0.02;
  const Eigen::Vector2d e(0.1, -0.04);
  PositionPidState s;
  for (int i = 1; i <= 1500; ++i) {
    const TiltSetpoint t = position_pid(k, s, e, {0, 0}, {0, 0}, 0.3, kG, dt);
    ASSERT_FALSE(t.saturated);
    for (int ax = 0; ax < 2; ++ax) {
      const double free = i * e[ax] * dt;  // the unbounded integral
      const double expected = std::clamp(free, -k.integral_limit, k.integral_limit);
      ASSERT_NEAR(s.integral_m_s[ax], expected, 1e-12) << "step " << i << " axis " << ax;
      ASSERT_LE(std::abs(s.integral_m_s[ax]), k.integral_limit);
    }
  }
  // x reached its limit (0.1 * 0.02 * 1500 = 3 > 2); y has not (0.04 * 0.02 * 1500 = 1.2).
  EXPECT_EQ(s.integral_m_s.x(), k.integral_limit);
  EXPECT_NEAR(s.integral_m_s.y(), -1.2, 1e-12);
}

TEST(PositionPid, AntiWindupStopsTheIntegralWhileSaturated) {
  // A large persistent error: saturated from the first step, the integral never grows.
  {
    const PositionGains k = brisk_gains();
    PositionPidState s;
    for (int i = 0; i < 2000; ++i) {
      const TiltSetpoint t = position_pid(k, s, {100, -40}, {0, 0}, {0, 0}, 0.5, kG, 0.02);
      ASSERT_TRUE(t.saturated);
      ASSERT_LE(std::abs(s.integral_m_s.x()), k.integral_limit);
      ASSERT_LE(std::abs(s.integral_m_s.y()), k.integral_limit);
    }
    EXPECT_EQ(s.integral_m_s, Eigen::Vector2d::Zero());
  }
  // The integral itself drives the output into saturation: it grows by e dt per step until the
  // unclamped pitch (kp e + ki I) / g first exceeds max_tilt, then freezes.
  {
    PositionGains k;
    k.kp = 0.1;
    k.ki = 1.0;
    k.kd = 0.0;
    k.integral_limit = 10.0;
    const double dt = 0.02, e = 1.0;
    const double I_star = (k.max_tilt_rad * kG - k.kp * e) / k.ki;  // = 3.3335
    PositionPidState s;
    double frozen_at = -1.0;
    for (int i = 0; i < 1000; ++i) {
      const double before = s.integral_m_s.x();
      const bool will_saturate = (k.kp * e + k.ki * before) / kG > k.max_tilt_rad;
      const TiltSetpoint t = position_pid(k, s, {e, 0}, {0, 0}, {0, 0}, 0.0, kG, dt);
      EXPECT_EQ(t.saturated, will_saturate) << "step " << i;
      if (will_saturate) {
        ASSERT_EQ(s.integral_m_s.x(), before) << "integral grew while saturated at step " << i;
        if (frozen_at < 0) frozen_at = before;
        EXPECT_EQ(t.pitch_rad, k.max_tilt_rad);
      } else {
        ASSERT_NEAR(s.integral_m_s.x(), before + e * dt, 1e-12);
      }
    }
    EXPECT_GT(frozen_at, I_star);
    EXPECT_LE(frozen_at, I_star + e * dt + 1e-12);
    EXPECT_LE(s.integral_m_s.x(), k.integral_limit);

    // Saturated but the error reversed: integrating now reduces the output, so it is allowed.
    s.integral_m_s = {9.0, 0.0};
    const TiltSetpoint t = position_pid(k, s, {-0.5, 0}, {0, 0}, {0, 0}, 0.0, kG, dt);
    EXPECT_TRUE(t.saturated);
    EXPECT_NEAR(s.integral_m_s.x(), 9.0 - 0.5 * dt, 1e-12);
  }
}

// ---------------------------------------------------------------------------------------------------
// PaperController (Algorithm 1, lines 6-20; the stale-data safety of lines 3-5 is the controller
// node's, tested in src/sim/sim_test.cpp).

// sqrt(m g / (4 kt)) from Table 1, the number in docs/model.md (~4830.6 rad/s).
double hover_speed() { return std::sqrt(kMass * kG / (4.0 * kKt)); }

Observation hover_observation(double z) {
  Observation e;
  e.p_W = {0.0, 0.0, z};
  e.age_s = 0.0;
  return e;
}

Reference hold(double z) {
  Reference r;
  r.p_W = {0.0, 0.0, z};
  return r;
}

// One step, with `outputs` sized as the node sizes it.
ControllerOutput step(Controller& c, const Observation& e, const Reference& r, double dt_s) {
  ControllerOutput out;
  out.outputs.assign(c.output_names().size(), kNaN);
  c.step(e, r, dt_s, out);
  return out;
}

// The output named `name` of `c`'s step.
double output(const Controller& c, const ControllerOutput& out, const std::string& name) {
  const auto names = c.output_names();
  const auto it = std::find(names.begin(), names.end(), name);
  if (it == names.end()) {
    ADD_FAILURE() << "no output named " << name;
    return kNaN;
  }
  return out.outputs.at(static_cast<std::size_t>(it - names.begin()));
}

TEST(PaperController, HoverSpeedIsTable1Value) { EXPECT_NEAR(hover_speed(), 4830.6, 0.05); }

TEST(PaperController, OutputsAreThePapersErrors) {
  const PaperController pc{VehicleParams{}};
  const auto names = pc.output_names();
  EXPECT_EQ(std::vector<std::string>(names.begin(), names.end()),
            (std::vector<std::string>{"error.z", "error.roll", "error.pitch", "error.yaw"}));
  EXPECT_EQ(pc.type(), "paper");
}

TEST(PaperController, HoverCommandsHoverSpeedOnAllRotors) {
  PaperController fc{VehicleParams{}};
  for (double z : {0.0, 5.0, 100.0}) {
    const ControllerOutput c = step(fc, hover_observation(z), hold(z), 0.02);
    EXPECT_FALSE(c.safety);
    EXPECT_EQ(c.U[0], kMass * kG);
    EXPECT_EQ(c.U.tail<3>(), Eigen::Vector3d::Zero());
    for (int i = 0; i < 4; ++i) {
      EXPECT_NEAR(c.omega_rad_s[i], hover_speed(), 1e-10 * hover_speed()) << "rotor " << i + 1;
      EXPECT_FALSE(c.rotor_saturated[i]);
    }
  }
}

TEST(PaperController, RollErrorGivesPositiveTorqueAndRotor4FasterThanRotor2) {
  const PaperParams p;
  const VehicleParams vehicle;
  PaperController fc(vehicle, p);
  Reference sp = hold(5.0);
  sp.roll_rad = 0.1;
  const ControllerOutput c = step(fc, hover_observation(5.0), sp, 0.02);
  ASSERT_FALSE(c.safety);
  // U2 = k1 e with k1 = sqrt(q_angle / r) (closed form, see care_test.cpp).
  const double k1 = std::sqrt(p.roll.q_angle / p.roll.r);
  EXPECT_GT(c.U[1], 0.0);
  EXPECT_NEAR(c.U[1], k1 * 0.1, 1e-10 * k1);
  EXPECT_NEAR(output(fc, c, "error.roll"), 0.1, 0.0);
  const Eigen::Vector4d w2 = squared(c.omega_rad_s);
  // Eq. (4): U2 = L kt (w4^2 - w2^2): rotor 4 (left, +y) speeds up, rotor 2 (right) slows down.
  EXPECT_GT(c.omega_rad_s[3], c.omega_rad_s[1]);
  EXPECT_GT(c.omega_rad_s[3], hover_speed());
  EXPECT_LT(c.omega_rad_s[1], hover_speed());
  EXPECT_NEAR(kL * kKt * (w2[3] - w2[1]), c.U[1], 1e-9 * c.U[1]);
  // No pitch or yaw torque, and the weight still carried.
  EXPECT_NEAR(c.omega_rad_s[0], c.omega_rad_s[2], 1e-9 * hover_speed());
  EXPECT_NEAR(kKm * (w2[0] - w2[1] + w2[2] - w2[3]), 0.0, 1e-9 * kKm * w2.sum());
  EXPECT_NEAR(kKt * w2.sum(), kMass * kG, 1e-9 * kMass * kG);
}

TEST(PaperController, PitchAndYawErrorsDriveTheRotorsEq4Implies) {
  const PaperParams p;
  const VehicleParams vehicle;
  PaperController fc(vehicle, p);
  {
    Reference sp = hold(5.0);
    sp.pitch_rad = 0.15;
    const ControllerOutput c = step(fc, hover_observation(5.0), sp, 0.02);
    // U3 = L kt (w3^2 - w1^2) > 0: rotor 3 (tail) faster than rotor 1 (nose).
    EXPECT_NEAR(c.U[2], std::sqrt(p.pitch.q_angle / p.pitch.r) * 0.15, 1e-10);
    EXPECT_GT(c.omega_rad_s[2], c.omega_rad_s[0]);
    const Eigen::Vector4d w2 = squared(c.omega_rad_s);
    EXPECT_NEAR(kL * kKt * (w2[2] - w2[0]), c.U[2], 1e-9 * c.U[2]);
  }
  {
    // Yaw authority is small (k_m / k_t ~ 5e-4 m): 0.01 rad keeps every rotor inside its range.
    Reference sp = hold(5.0);
    sp.yaw_rad = 0.01;
    const ControllerOutput c = step(fc, hover_observation(5.0), sp, 0.02);
    for (int i = 0; i < 4; ++i) ASSERT_FALSE(c.rotor_saturated[i]);
    // U4 = km (w1^2 - w2^2 + w3^2 - w4^2) > 0: rotors 1 and 3 faster than 2 and 4.
    EXPECT_NEAR(c.U[3], std::sqrt(p.yaw.q_angle / p.yaw.r) * 0.01, 1e-12);
    EXPECT_GT(c.omega_rad_s[0], c.omega_rad_s[1]);
    EXPECT_GT(c.omega_rad_s[2], c.omega_rad_s[3]);
    const Eigen::Vector4d w2 = squared(c.omega_rad_s);
    EXPECT_NEAR(kKm * (w2[0] - w2[1] + w2[2] - w2[3]), c.U[3], 1e-8 * c.U[3]);
  }
  {
    // A body rate is damped: positive roll rate, no error -> negative roll torque -k2 p.
    Observation e = hover_observation(5.0);
    e.w_B = {0.5, 0.0, 0.0};
    const ControllerOutput c = step(fc, e, hold(5.0), 0.02);
    const double k1 = std::sqrt(p.roll.q_angle / p.roll.r);
    const double k2 = std::sqrt(p.roll.q_rate / p.roll.r + 2.0 * vehicle.Ixx_kg_m2 * k1);
    EXPECT_NEAR(c.U[1], -k2 * 0.5, 1e-10);
  }
}

TEST(PaperController, YawErrorIsWrapped) {
  const PaperParams p;
  const VehicleParams vehicle;
  PaperController fc(vehicle, p);
  const double k1 = std::sqrt(p.yaw.q_angle / p.yaw.r);
  struct Case {
    double des, yaw, error;
  };
  for (const Case c : {Case{kPi - 0.1, -kPi + 0.1, -0.2}, Case{-kPi + 0.1, kPi - 0.1, 0.2},
                       Case{3.0, -3.0, 6.0 - 2 * kPi}, Case{0.3, 0.1, 0.2}, Case{2 * kPi - 0.05, 0.05, -0.1}}) {
    SCOPED_TRACE(testing::Message() << "des " << c.des << " yaw " << c.yaw);
    Reference sp = hold(5.0);
    sp.yaw_rad = c.des;
    Observation e = hover_observation(5.0);
    e.yaw_rad = c.yaw;
    const ControllerOutput cmd = step(fc, e, sp, 0.02);
    EXPECT_NEAR(output(fc, cmd, "error.yaw"), c.error, 1e-12);
    EXPECT_NEAR(cmd.U[3], k1 * c.error, 1e-12);
  }
}

TEST(PaperController, PositionModeTiltsTowardsTheTarget) {
  PaperController fc{VehicleParams{}};
  Reference sp = hold(5.0);
  sp.mode = Mode::kPosition;
  sp.p_W.x() = 0.5;
  const ControllerOutput c = step(fc, hover_observation(5.0), sp, 0.02);
  EXPECT_GT(c.pitch_des_rad, 0.0);
  EXPECT_EQ(c.roll_des_rad, 0.0);
  EXPECT_GT(c.U[2], 0.0);
  EXPECT_GT(c.omega_rad_s[2], c.omega_rad_s[0]);  // tail up, nose down, thrust towards +x
  // The reference's attitude setpoints are ignored in position mode.
  sp.roll_rad = 1.0;
  PaperController fc2{VehicleParams{}};
  EXPECT_EQ(step(fc2, hover_observation(5.0), sp, 0.02).roll_des_rad, 0.0);
}

// Every parameter of a controller, by name, for before/after comparisons.
std::vector<std::pair<std::string, ParameterValue>> snapshot(const Controller& c) {
  std::vector<std::pair<std::string, ParameterValue>> out;
  for (const auto& spec : c.parameters()) out.emplace_back(std::string(spec.name), *c.get_parameter(spec.name));
  return out;
}

TEST(PaperController, RefusedSettingsChangeNothingAndTheConstructorThrows) {
  const PaperParams good;
  const VehicleParams vehicle;
  PaperController fc(vehicle, good);
  Reference sp = hold(5.0);
  sp.mode = Mode::kPosition;
  sp.p_W.x() = 1.0;
  Observation e = hover_observation(4.8);
  e.roll_rad = 0.05;
  e.w_B = {0.1, -0.2, 0.3};
  for (int i = 0; i < 5; ++i) step(fc, e, sp, 0.02);

  const auto K_before = std::array<Eigen::RowVector2d, 3>{fc.axis(0).K, fc.axis(1).K, fc.axis(2).K};
  const PositionPidState state_before = fc.position_state();
  const auto params_before = snapshot(fc);
  PaperController reference = fc;  // an untouched copy to compare the next step with

  struct Case {
    std::vector<Setting> settings;
    std::string needle;  // what the refusal must name
  };
  const std::vector<Case> bad = {
      {{{"lqr.roll.r", 0.0}}, "lqr.roll.r"},
      // Fails on the last axis, after roll and pitch designed fine.
      {{{"lqr.yaw.q_angle", 0.0}}, "lqr.yaw.q_angle"},
      {{{"lqr.pitch.q_rate", -1.0}}, "lqr.pitch.q_rate"},
      // A good change bundled with a bad one.
      {{{"altitude.kp", 99.0}, {"lqr.yaw.r", -1.0}}, "lqr.yaw.r"},
  };
  for (std::size_t i = 0; i < bad.size(); ++i) {
    SCOPED_TRACE(i);
    const std::string err = fc.set_parameters(bad[i].settings);
    EXPECT_NE(err.find(bad[i].needle), std::string::npos) << err;
    EXPECT_EQ(fc.params().roll.r, good.roll.r);
    EXPECT_EQ(fc.params().yaw.q_angle, good.yaw.q_angle);
    EXPECT_EQ(fc.params().altitude.kp, good.altitude.kp);
    EXPECT_EQ(snapshot(fc), params_before);
    for (int a = 0; a < 3; ++a) EXPECT_EQ(fc.axis(a).K, K_before[a]);
    EXPECT_EQ(fc.position_state().integral_m_s, state_before.integral_m_s);
  }
  const ControllerOutput c1 = step(fc, e, sp, 0.02), c2 = step(reference, e, sp, 0.02);
  EXPECT_EQ(c1.omega_rad_s, c2.omega_rad_s);
  EXPECT_EQ(c1.U, c2.U);

  // The constructor throws for a design with no solution, of the weights or of the vehicle.
  PaperParams bad_roll = good;
  bad_roll.roll.r = 0.0;
  EXPECT_THROW(PaperController(vehicle, bad_roll), CareError);
  VehicleParams no_inertia = vehicle;
  no_inertia.Izz_kg_m2 = 0.0;
  EXPECT_THROW(PaperController{no_inertia}, CareError);

  // A valid change applies (K follows the closed form) and keeps the integrator.
  const PositionPidState s = fc.position_state();
  const std::vector<Setting> better = {{"lqr.roll.q_angle", 4.0}, {"lqr.roll.q_rate", 1.0}, {"lqr.roll.r", 25.0}};
  EXPECT_EQ(fc.set_parameters(better), "");
  EXPECT_NEAR(-fc.axis(0).K(0), std::sqrt(4.0 / 25.0), 1e-10);
  EXPECT_EQ(fc.params().roll.q_rate, 1.0);
  EXPECT_EQ(fc.position_state().integral_m_s, s.integral_m_s);
}

// ControllerWith::set_parameters applies a batch all together or not at all.
TEST(ControllerWith, SetParametersIsAllOrNothing) {
  PaperController pc{VehicleParams{}};
  const auto before = snapshot(pc);
  const auto K_before = std::array<Eigen::RowVector2d, 3>{pc.axis(0).K, pc.axis(1).K, pc.axis(2).K};
  const auto unchanged = [&] {
    EXPECT_EQ(snapshot(pc), before);
    for (int a = 0; a < 3; ++a) EXPECT_EQ(pc.axis(a).K, K_before[a]);
  };
  // Valid values first, then one out of range: nothing of the batch is applied; the refusal names it.
  {
    const std::vector<Setting> batch = {
        {"altitude.kp", 7.5}, {"lqr.pitch.q_angle", 3.0}, {"position.max_tilt", 5.0}, {"position.kd", 1.0}};
    const std::string err = pc.set_parameters(batch);
    EXPECT_NE(err.find("position.max_tilt"), std::string::npos) << err;
    unchanged();
  }
  // An unknown name, a string for a number, NaN: each refused, nothing applied.
  for (const Setting& wrong :
       {Setting{"lqr.roll.nope", 1.0}, Setting{"altitude.kd", std::string("3")}, Setting{"altitude.kd", kNaN}}) {
    SCOPED_TRACE(wrong.name);
    const std::vector<Setting> batch = {{"altitude.kp", 7.5}, wrong};
    const std::string err = pc.set_parameters(batch);
    EXPECT_NE(err.find(wrong.name), std::string::npos) << err;
    unchanged();
  }
  // Every value in range and the design still solvable at the smallest angle weight the table
  // allows (q_angle > 0 keeps the angle detectable in the cost, see care_test.cpp).
  {
    const std::vector<Setting> batch = {{"lqr.yaw.q_angle", 1e-12}, {"lqr.yaw.r", 1e9}};
    quadcosim::controllers::PaperController other = pc;
    EXPECT_EQ(other.set_parameters(batch), "");
    EXPECT_TRUE(other.axis(2).K.allFinite());
  }
  // The same batch without the bad one applies every value, with one design.
  const std::vector<Setting> ok = {{"altitude.kp", 7.5}, {"lqr.roll.q_angle", 2.0}};
  EXPECT_EQ(pc.set_parameters(ok), "");
  EXPECT_EQ(std::get<double>(*pc.get_parameter("altitude.kp")), 7.5);
  EXPECT_EQ(std::get<double>(*pc.get_parameter("lqr.roll.q_angle")), 2.0);
  EXPECT_NEAR(-pc.axis(0).K(0), std::sqrt(2.0 / PaperParams{}.roll.r), 1e-10);
  EXPECT_EQ(pc.axis(2).K, K_before[2]);
}

namespace {
// A controller whose design refuses lo > hi: each value is in range on its own, the pair is not.
struct BandParams {
  double lo = 1.0, hi = 2.0;
};
class BandController : public quadcosim::control::ControllerWith<BandController, BandParams> {
 public:
  BandController() : ControllerWith(BandParams{}) {}
  std::string_view type() const override { return "band"; }
  std::span<const std::string> output_names() const override { return {}; }
  void reset() override {}
  void step(const quadcosim::control::Observation&, const quadcosim::control::Reference&, double,
            quadcosim::control::ControllerOutput&) override {}
  int designs = 0;

 protected:
  const quadcosim::control::ParameterTable<BandParams>& table() const override {
    using T = quadcosim::control::ParameterTable<BandParams>;
    static const T t({T::number(
                          "lo", "", 0, 10, "lower", [](auto& p) -> auto& { return p.lo; }),
                      T::number(
                          "hi", "", 0, 10, "upper", [](auto& p) -> auto& { return p.hi; })});
    return t;
  }
  void configure(const BandParams& next) override {
    if (next.lo > next.hi) throw std::invalid_argument("lo must not exceed hi");
    ++designs;
  }
};
}  // namespace

// A batch that the design refuses (each value in range) is refused naming every setting and the
// reason, and changes nothing; a batch is designed once.
TEST(ControllerWith, ADesignThatFailsRefusesTheWholeBatch) {
  using quadcosim::control::Setting;
  BandController c;
  const std::vector<Setting> bad = {{"hi", 4.0}, {"lo", 5.0}};
  const std::string err = c.set_parameters(bad);
  for (const char* n : {"hi", "lo", "lo must not exceed hi"}) EXPECT_NE(err.find(n), std::string::npos) << err;
  EXPECT_EQ(c.params().lo, 1.0);
  EXPECT_EQ(c.params().hi, 2.0);
  EXPECT_EQ(c.designs, 0);
  const std::vector<Setting> ok = {{"hi", 6.0}, {"lo", 5.0}};
  EXPECT_EQ(c.set_parameters(ok), "");
  EXPECT_EQ(c.params().lo, 5.0);
  EXPECT_EQ(c.params().hi, 6.0);
  EXPECT_EQ(c.designs, 1);
  const auto copy = c.clone();
  EXPECT_EQ(std::get<double>(*copy->get_parameter("lo")), 5.0);
}

// Psi = 1/2 tr(I - R_d^T R) = 1 - cos(theta) for attitudes a rotation by theta apart.
TEST(AttitudeError, IsOneMinusCosineOfTheAngleBetween) {
  const std::vector<Eigen::Vector3d> axes = {Eigen::Vector3d::UnitX(), Eigen::Vector3d::UnitY(),
                                             Eigen::Vector3d::UnitZ(), Eigen::Vector3d(1, -2, 0.5).normalized()};
  const std::vector<Eigen::Quaterniond> bases = {
      Eigen::Quaterniond::Identity(),
      Eigen::Quaterniond(Eigen::AngleAxisd(0.7, Eigen::Vector3d(0.3, 1, -0.2).normalized())),
      Eigen::Quaterniond(Eigen::AngleAxisd(-2.5, Eigen::Vector3d::UnitZ()))};
  for (const auto& q_des : bases) {
    for (const auto& axis : axes) {
      for (double theta : {0.0, 1e-3, 0.1, 0.5, kPi / 2, 2.0, 3.0, kPi}) {
        SCOPED_TRACE(testing::Message() << "axis " << axis.transpose() << " theta " << theta);
        const Eigen::Quaterniond q = q_des * Eigen::Quaterniond(Eigen::AngleAxisd(theta, axis));
        EXPECT_NEAR(attitude_error(q_des, q), 1.0 - std::cos(theta), 1e-12);
        EXPECT_NEAR(attitude_error(q, q_des), 1.0 - std::cos(theta), 1e-12);  // symmetric
        // The sign of a quaternion does not matter: -q is the same attitude.
        EXPECT_NEAR(attitude_error(q_des, Eigen::Quaterniond(-q.coeffs())), 1.0 - std::cos(theta), 1e-12);
      }
    }
  }
  // The range ends: 0 for equal attitudes, 2 for opposite ones (a half turn).
  EXPECT_EQ(attitude_error(Eigen::Quaterniond::Identity(), Eigen::Quaterniond::Identity()), 0.0);
  EXPECT_NEAR(attitude_error(Eigen::Quaterniond::Identity(),
                             Eigen::Quaterniond(Eigen::AngleAxisd(kPi, Eigen::Vector3d::UnitY()))),
              2.0, 1e-15);
}

// ---------------------------------------------------------------------------------------------------
// Parameters.

// Every parameter's current value, by name, for before/after comparisons.
std::vector<std::pair<std::string, ParameterValue>> snapshot(const ControllerConfig& c) {
  std::vector<std::pair<std::string, ParameterValue>> out;
  for (const ParameterSpec* spec : all_parameters(c))
    out.emplace_back(std::string(spec->name), *get_parameter(c, spec->name));
  return out;
}

// The paper controller's configuration for the Table 1 vehicle.
ControllerConfig paper_config() { return quadcosim::controllers::make_config("paper", VehicleParams{}); }

const PaperParams& paper_params(const ControllerConfig& c) {
  const PaperController* pc = quadcosim::controllers::paper_controller(c);
  if (pc == nullptr) throw std::logic_error("not a paper controller");
  return pc->params();
}

void expect_refused(ControllerConfig& config, const std::string& name, const ParameterValue& v,
                    const std::vector<std::string>& needles) {
  SCOPED_TRACE(testing::Message() << name << " = " << to_string(v));
  const auto before = snapshot(config);
  const ControllerConfig raw_before = config;
  const std::string err = set_parameter(config, name, v);
  EXPECT_FALSE(err.empty());
  for (const auto& n : needles) EXPECT_NE(err.find(n), std::string::npos) << "'" << err << "' lacks '" << n << "'";
  EXPECT_EQ(snapshot(config), before);
  // Spot checks on the raw struct too.
  EXPECT_EQ(config.node.setpoint.p_des_W, raw_before.node.setpoint.p_des_W);
  EXPECT_EQ(config.node.setpoint.mode, raw_before.node.setpoint.mode);
  EXPECT_EQ(paper_params(config).roll.r, paper_params(raw_before).roll.r);
  EXPECT_EQ(config.node.safety, raw_before.node.safety);
}

TEST(Parameters, RefusesBadValuesNamingTheParameter) {
  ControllerConfig c = paper_config();
  ASSERT_EQ(set_parameter(c, "z_des", 3.0), "");
  expect_refused(c, "z_dse", 1.0, {"unknown", "z_dse"});
  expect_refused(c, "", 1.0, {"unknown"});
  expect_refused(c, "z_des", 1e6, {"z_des", "100000"});  // names the range
  expect_refused(c, "z_des", -1e4, {"z_des"});
  expect_refused(c, "z_des", kNaN, {"z_des", "nan"});
  expect_refused(c, "z_des", kInf, {"z_des"});
  expect_refused(c, "z_des", std::string("10"), {"z_des", "number"});
  expect_refused(c, "lqr.roll.r", 0.0, {"lqr.roll.r"});
  expect_refused(c, "lqr.yaw.q_rate", -1.0, {"lqr.yaw.q_rate"});
  expect_refused(c, "altitude.min_cos_tilt", 0.0, {"altitude.min_cos_tilt"});
  expect_refused(c, "altitude.min_cos_tilt", 1.5, {"altitude.min_cos_tilt"});
  expect_refused(c, "stale_limit", 0.0, {"stale_limit"});
  expect_refused(c, "mode", std::string("hover"), {"mode", "attitude", "position", "hover"});
  expect_refused(c, "mode", std::string("Position"), {"mode"});
  expect_refused(c, "mode", 1.0, {"mode"});
  expect_refused(c, "safety_mode", std::string("land"), {"safety_mode", "stop", "hover"});
  expect_refused(c, "safety_mode", std::string(""), {"safety_mode"});
  EXPECT_EQ(c.node.setpoint.p_des_W.z(), 3.0);
}

TEST(Parameters, GetAfterSetReturnsTheValueAndWritesTheField) {
  ControllerConfig c = paper_config();
  EXPECT_EQ(set_parameter(c, "z_des", 10.0), "");
  EXPECT_EQ(c.node.setpoint.p_des_W.z(), 10.0);
  EXPECT_EQ(std::get<double>(*get_parameter(c, "z_des")), 10.0);
  EXPECT_EQ(set_parameter(c, "x_des", -2.5), "");
  EXPECT_EQ(c.node.setpoint.p_des_W.x(), -2.5);
  EXPECT_EQ(set_parameter(c, "lqr.pitch.r", 42.0), "");
  EXPECT_EQ(paper_params(c).pitch.r, 42.0);
  EXPECT_EQ(set_parameter(c, "position.max_tilt", 0.2), "");
  EXPECT_EQ(paper_params(c).position.max_tilt_rad, 0.2);
  EXPECT_EQ(set_parameter(c, "mode", std::string("position")), "");
  EXPECT_EQ(c.node.setpoint.mode, Mode::kPosition);
  EXPECT_EQ(std::get<std::string>(*get_parameter(c, "mode")), "position");
  EXPECT_EQ(set_parameter(c, "mode", std::string("attitude")), "");
  EXPECT_EQ(c.node.setpoint.mode, Mode::kAttitude);
  EXPECT_EQ(set_parameter(c, "safety_mode", std::string("hover")), "");
  EXPECT_EQ(c.node.safety, SafetyMode::kHover);
  EXPECT_EQ(std::get<std::string>(*get_parameter(c, "safety_mode")), "hover");
  EXPECT_FALSE(get_parameter(c, "nope").has_value());

  // Every numeric parameter: both ends of the range and a value inside round-trip exactly, and only
  // that parameter changes.
  for (const ParameterSpec* p : all_parameters(c)) {
    const ParameterSpec& spec = *p;
    SCOPED_TRACE(std::string(spec.name));
    if (spec.is_choice()) {
      for (auto choice : spec.choices) {
        EXPECT_EQ(set_parameter(c, spec.name, std::string(choice)), "");
        EXPECT_EQ(std::get<std::string>(*get_parameter(c, spec.name)), choice);
      }
      continue;
    }
    const double inside = spec.min + 0.37 * (std::min(spec.max, spec.min + 10.0) - spec.min);
    for (double v : {spec.min, spec.max, inside}) {
      auto before = snapshot(c);
      EXPECT_EQ(set_parameter(c, spec.name, v), "");
      EXPECT_EQ(std::get<double>(*get_parameter(c, spec.name)), v);
      auto after = snapshot(c);
      for (std::size_t i = 0; i < before.size(); ++i) {
        if (after[i].first != spec.name) {
          EXPECT_EQ(after[i], before[i]) << after[i].first << " changed too";
        }
      }
    }
  }
}

TEST(Parameters, TableIsWellFormedAndDefaultsAreInRange) {
  const ControllerConfig defaults = paper_config();
  const auto table = all_parameters(defaults);
  ASSERT_FALSE(table.empty());
  std::vector<std::string> names;
  for (const ParameterSpec* p : table) {
    const ParameterSpec& spec = *p;
    SCOPED_TRACE(std::string(spec.name));
    EXPECT_FALSE(spec.name.empty());
    EXPECT_FALSE(spec.description.empty());
    EXPECT_EQ(find_parameter(defaults, spec.name), &spec);
    for (const auto& n : names) EXPECT_NE(n, spec.name) << "duplicate name";
    names.emplace_back(spec.name);
    const ParameterValue v = *get_parameter(defaults, spec.name);
    if (spec.is_choice()) {
      EXPECT_EQ(spec.unit, "choice");
      ASSERT_TRUE(std::holds_alternative<std::string>(v));
      const auto& s = std::get<std::string>(v);
      EXPECT_NE(std::find(spec.choices.begin(), spec.choices.end(), s), spec.choices.end()) << s;
    } else {
      ASSERT_TRUE(std::holds_alternative<double>(v));
      const double d = std::get<double>(v);
      EXPECT_LE(spec.min, spec.max);
      EXPECT_GE(d, spec.min);
      EXPECT_LE(d, spec.max);
      // Setting the default back is accepted.
      ControllerConfig c = paper_config();
      EXPECT_EQ(set_parameter(c, spec.name, d), "");
    }
  }
  // The documented names the rest of the project relies on exist.
  for (const char* n : {"mode", "x_des", "y_des", "z_des", "roll_des", "pitch_des", "yaw_des", "altitude.kp",
                        "altitude.kd", "lqr.roll.q_angle", "lqr.yaw.r", "position.kp", "stale_limit", "safety_mode"}) {
    EXPECT_NE(find_parameter(defaults, n), nullptr) << n;
  }
  EXPECT_EQ(find_parameter(defaults, "no_such"), nullptr);
}

}  // namespace

namespace {

// A controller that decides only rotor speeds (Python, FMU) says what it tracks through the outputs it
// declares; without them, roll and pitch in position mode are unknown (NaN), not a level 0.
TEST(RotorSpeedsOutput, ReportedOutputsFillTheTrackedAttitudeAndTiltFlag) {
  VehicleParams v;
  const quadcosim::model::Quadrotor model(v);
  const std::vector<std::string> names = {"thrust_N", "pitch_des", "tilt_saturated", "roll_des"};
  const ReportedOutputs reported = ReportedOutputs::find(names);
  EXPECT_EQ(reported.roll_des, 3);
  EXPECT_EQ(reported.pitch_des, 1);
  EXPECT_EQ(reported.yaw_des, -1);
  EXPECT_EQ(reported.tilt_saturated, 2);

  Reference position;
  position.mode = Mode::kPosition;
  position.yaw_rad = 0.3;
  ControllerOutput out;
  out.outputs = {19.2, -0.05, 1.0, 0.08};
  const Eigen::Vector4d omega = Eigen::Vector4d::Constant(5000.0);
  rotor_speeds_output(model, position, omega, reported, out);
  EXPECT_EQ(out.roll_des_rad, 0.08);
  EXPECT_EQ(out.pitch_des_rad, -0.05);
  EXPECT_EQ(out.yaw_des_rad, 0.3);  // not declared: the reference's
  EXPECT_TRUE(out.tilt_saturated);
  // U is the wrench of the commanded speeds: 4 k_t omega^2 of thrust, no torque at equal speeds.
  EXPECT_NEAR(out.U[0], 4.0 * v.kt_N_per_rad2_s2 * 5000.0 * 5000.0, 1e-9 * out.U[0]);

  ControllerOutput silent;
  rotor_speeds_output(model, position, omega, ReportedOutputs::find({}), silent);
  EXPECT_TRUE(std::isnan(silent.roll_des_rad));
  EXPECT_TRUE(std::isnan(silent.pitch_des_rad));
  EXPECT_EQ(silent.yaw_des_rad, 0.3);
  EXPECT_FALSE(silent.tilt_saturated);

  Reference attitude;  // attitude mode: the reference's setpoints are what is tracked
  attitude.roll_rad = 0.1;
  attitude.pitch_rad = -0.2;
  rotor_speeds_output(model, attitude, omega, ReportedOutputs::find({}), silent);
  EXPECT_EQ(silent.roll_des_rad, 0.1);
  EXPECT_EQ(silent.pitch_des_rad, -0.2);
}

TEST(RotorSpeedsOutput, ARotorCommandedAtOrBeyondItsLimitsIsSaturated) {
  VehicleParams v;
  v.motor.omega_min_rad_s = 100.0;
  v.motor.omega_max_rad_s = 9000.0;
  const quadcosim::model::Quadrotor model(v);
  ControllerOutput out;
  const Eigen::Vector4d omega(9000.0, 8999.999, 100.0, 100.001);
  rotor_speeds_output(model, Reference{}, omega, ReportedOutputs{}, out);
  EXPECT_EQ(out.rotor_saturated, (std::array<bool, 4>{true, false, true, false}));
  rotor_speeds_output(model, Reference{}, Eigen::Vector4d(1e4, 0.0, 5000.0, 5000.0), ReportedOutputs{}, out);
  EXPECT_EQ(out.rotor_saturated, (std::array<bool, 4>{true, true, false, false}));
}

}  // namespace
