// The SE(3) geometric controller: its error terms against closed forms, exact hover, and flights on
// model::Quadrotor (first-order motors, plant at 100 Hz, controller at 50 Hz).
#include "controllers/se3/geometric_controller.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <vector>

#include "control/observation_test_support.hpp"
#include "model/attitude.hpp"
#include "model/mixer.hpp"
#include "model/quadrotor.hpp"
#include "model/vehicle_presets.hpp"

namespace quadcosim::controllers {
namespace {

using control::ControllerOutput;
using control::Mode;
using control::Observation;
using control::Reference;
using control::Setting;
using control::test::observe;

constexpr double kPi = 3.14159265358979323846;
constexpr double kControlDt = 0.02;       // 50 Hz
constexpr int kPlantStepsPerControl = 2;  // 100 Hz

model::VehicleParams lagged_vehicle() {
  model::VehicleParams v;                          // Table 1
  v.motor.model = model::MotorModel::kFirstOrder;  // tau 0.02 s up, 0.04 s down
  return v;
}

ControllerOutput new_output(const control::Controller& c) {
  ControllerOutput out;
  out.outputs.assign(c.output_names().size(), std::nan(""));
  return out;
}

int output_index(const control::Controller& c, const std::string& name) {
  const auto names = c.output_names();
  for (std::size_t i = 0; i < names.size(); ++i) {
    if (names[i] == name) return static_cast<int>(i);
  }
  ADD_FAILURE() << "no output " << name;
  return 0;
}

Reference hold_position(const Eigen::Vector3d& p_W, double yaw_rad) {
  Reference r;
  r.mode = Mode::kPosition;
  r.p_W = p_W;
  r.yaw_rad = yaw_rad;
  return r;
}

// --- 1. e_R and Psi against their closed forms -------------------------------------------------

TEST(GeometricController, AttitudeErrorMatchesClosedForm) {
  const Eigen::Matrix3d R_d =
      (Eigen::AngleAxisd(0.7, Eigen::Vector3d::UnitZ()) * Eigen::AngleAxisd(-0.3, Eigen::Vector3d::UnitY()) *
       Eigen::AngleAxisd(0.2, Eigen::Vector3d::UnitX()))
          .toRotationMatrix();
  const std::vector<Eigen::Vector3d> axes = {Eigen::Vector3d::UnitX(), Eigen::Vector3d::UnitY(),
                                             Eigen::Vector3d::UnitZ(), Eigen::Vector3d(1, -2, 0.5).normalized(),
                                             Eigen::Vector3d(-0.3, 0.4, -1).normalized()};
  for (const Eigen::Vector3d& a : axes) {
    for (double theta : {0.0, 0.01, 0.5, 1.5, 2.5, 3.0}) {
      const Eigen::Matrix3d R = R_d * Eigen::AngleAxisd(theta, a).toRotationMatrix();
      const Eigen::Vector3d e_R = attitude_error_vector(R_d, R);
      EXPECT_LT((e_R - std::sin(theta) * a).norm(), 1e-12) << "axis " << a.transpose() << " theta " << theta;
      EXPECT_NEAR(control::attitude_error(Eigen::Quaterniond(R_d), Eigen::Quaterniond(R)), 1.0 - std::cos(theta),
                  1e-12);
    }
  }
}

TEST(GeometricController, AttitudeModeReportsErrorAgainstTheReferenceAttitude) {
  GeometricController ctl(model::VehicleParams{});
  Reference ref;
  ref.mode = Mode::kAttitude;
  ref.roll_rad = 0.1;
  ref.pitch_rad = -0.2;
  ref.yaw_rad = 1.0;
  ref.p_W.z() = 3.0;
  const Eigen::Matrix3d R_d =
      (Eigen::AngleAxisd(1.0, Eigen::Vector3d::UnitZ()) * Eigen::AngleAxisd(-0.2, Eigen::Vector3d::UnitY()) *
       Eigen::AngleAxisd(0.1, Eigen::Vector3d::UnitX()))
          .toRotationMatrix();
  const Eigen::Vector3d a = Eigen::Vector3d(0.3, -1, 0.2).normalized();
  const double theta = 0.8;
  Observation obs;
  obs.p_W.z() = 3.0;
  obs.q_WB = Eigen::Quaterniond(R_d * Eigen::AngleAxisd(theta, a).toRotationMatrix());
  ControllerOutput out = new_output(ctl);
  ctl.step(obs, ref, kControlDt, out);
  const int ex = output_index(ctl, "e_R.x");
  EXPECT_NEAR(out.outputs[ex + 0], std::sin(theta) * a.x(), 1e-12);
  EXPECT_NEAR(out.outputs[ex + 1], std::sin(theta) * a.y(), 1e-12);
  EXPECT_NEAR(out.outputs[ex + 2], std::sin(theta) * a.z(), 1e-12);
  EXPECT_NEAR(out.attitude_error, 1.0 - std::cos(theta), 1e-12);
  EXPECT_EQ(out.roll_des_rad, 0.1);
  EXPECT_EQ(out.pitch_des_rad, -0.2);
  EXPECT_EQ(out.yaw_des_rad, 1.0);
  // At the held altitude and at rest, the thrust is m g over the tilt cosine (R e3)_z.
  const model::VehicleParams v;
  const double cos_tilt = obs.q_WB.toRotationMatrix()(2, 2);
  ASSERT_GT(cos_tilt, 0.5);
  EXPECT_NEAR(out.U[0], v.mass_kg * v.gravity_m_s2 / cos_tilt, 1e-9);
}

// --- 2. Exact hover -------------------------------------------------------------------------------

TEST(GeometricController, ExactHoverGivesHoverSpeedsAndZeroErrors) {
  const model::VehicleParams v;
  GeometricController ctl(v);
  const double yaw = 0.7;
  const Eigen::Vector3d p(1.0, -2.0, 5.0);
  Observation obs;
  obs.p_W = p;
  obs.q_WB = Eigen::Quaterniond(Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitZ()));
  obs.yaw_rad = yaw;
  ControllerOutput out = new_output(ctl);
  ctl.step(obs, hold_position(p, yaw), kControlDt, out);
  const GeometricTerms& t = ctl.terms();
  EXPECT_EQ(t.e_x_W.norm(), 0.0);
  EXPECT_EQ(t.e_v_W.norm(), 0.0);
  EXPECT_LT(t.e_R.norm(), 1e-15);
  EXPECT_LT(t.e_Omega_B.norm(), 1e-15);
  EXPECT_NEAR(out.U[0], v.mass_kg * v.gravity_m_s2, 1e-12);
  EXPECT_NEAR(out.outputs[output_index(ctl, "thrust")], v.mass_kg * v.gravity_m_s2, 1e-12);
  for (int i = 1; i < 4; ++i) EXPECT_NEAR(out.U[i], 0.0, 1e-14);
  const double hover = std::sqrt(v.mass_kg * v.gravity_m_s2 / (4.0 * v.kt_N_per_rad2_s2));
  ASSERT_NEAR(hover, v.hover_omega_rad_s(), 1e-9);
  for (int i = 0; i < 4; ++i) {
    EXPECT_NEAR(out.omega_rad_s[i], hover, 1e-9 * hover) << "rotor " << i;
    EXPECT_FALSE(out.rotor_saturated[i]);
  }
  EXPECT_LT(out.attitude_error, 1e-15);
  EXPECT_NEAR(out.yaw_des_rad, yaw, 1e-12);
  EXPECT_NEAR(out.roll_des_rad, 0.0, 1e-12);
  EXPECT_NEAR(out.pitch_des_rad, 0.0, 1e-12);
  EXPECT_FALSE(out.tilt_saturated);
}

TEST(GeometricController, YawTorqueGivesWayToThrustAndRollPitch) {
  // A 1 rad heading error with a stiff yaw gain asks for far more yaw torque than the rotors' drag can
  // give; the allocation keeps the thrust and zero roll/pitch torque and gives the largest yaw torque
  // left: two opposite rotors at 0, the other two carrying the weight, |M_z| = k_m 4 w_hover^2.
  const model::VehicleParams v;
  GeometricController ctl(v);
  ASSERT_EQ(ctl.set_parameters(std::vector<Setting>{{"k_R.z", 10.0}}), "");
  Reference ref;
  ref.mode = Mode::kAttitude;
  ref.yaw_rad = 1.0;
  Observation obs;  // level, yaw 0, at the held altitude 0
  ControllerOutput out = new_output(ctl);
  ctl.step(obs, ref, kControlDt, out);
  const double requested = 10.0 * std::sin(1.0);  // e_R.z = -sin(1): M_z = +10 sin(1)
  const double w2_hover = v.mass_kg * v.gravity_m_s2 / (4.0 * v.kt_N_per_rad2_s2);
  const double max_yaw = v.km_Nm_per_rad2_s2 * 4.0 * w2_hover;
  EXPECT_NEAR(out.U[3], max_yaw, 1e-12);
  EXPECT_NEAR(out.outputs[output_index(ctl, "yaw_torque_cut")], requested - max_yaw, 1e-9);
  const Eigen::Vector4d realised = model::mixer_matrix(v) * out.omega_rad_s.cwiseAbs2();
  EXPECT_NEAR(realised[0], v.mass_kg * v.gravity_m_s2, 1e-9);
  EXPECT_NEAR(realised[1], 0.0, 1e-9);
  EXPECT_NEAR(realised[2], 0.0, 1e-9);
  EXPECT_NEAR(realised[3], max_yaw, 1e-12);
}

// --- Closed loop on the plant ---------------------------------------------------------------------

/// Flies `ctl` on model::Quadrotor: at every 50 Hz tick it observes the state, steps, holds the command
/// over two 100 Hz RK4 steps. `reference(t)` gives the reference; `each(t, x, out)` sees every tick.
template <class RefFn, class EachFn>
void fly(const model::Quadrotor& plant, GeometricController& ctl, model::State& x, double duration_s, RefFn reference,
         EachFn each) {
  ControllerOutput out = new_output(ctl);
  const int ticks = static_cast<int>(std::lround(duration_s / kControlDt));
  for (int k = 0; k < ticks; ++k) {
    const double t = k * kControlDt;
    ctl.step(observe(x), reference(t), kControlDt, out);
    each(t, x, out);
    const model::RotorInput input = plant.rotor_input(out.omega_rad_s);
    for (int s = 0; s < kPlantStepsPerControl; ++s) {
      plant.step(x, t + s * kControlDt / kPlantStepsPerControl, input, kControlDt / kPlantStepsPerControl, 1);
    }
  }
}

struct Recovery {
  double attitude_settled_s = -1;  ///< from then on Psi < 1e-3
  double position_settled_s = -1;  ///< from then on |p - p_d| < 3 cm
  double final_position_error_m = 0;
  double min_altitude_m = 1e9;
  bool finite = true;
};

Recovery recover(const Eigen::Vector3d& axis, double angle_rad, double duration_s) {
  const model::VehicleParams v = lagged_vehicle();
  const model::Quadrotor plant(v);
  GeometricController ctl(v);
  const Eigen::Vector3d p_d(0.0, 0.0, 100.0);
  model::State x = plant.initial_state(p_d, 0.0, /*hover=*/true);
  x.q_WB = Eigen::Quaterniond(Eigen::AngleAxisd(angle_rad, axis.normalized()));
  Recovery r;
  fly(
      plant, ctl, x, duration_s, [&](double) { return hold_position(p_d, 0.0); },
      [&](double t, const model::State& s, const ControllerOutput& out) {
        const double psi = control::attitude_error(Eigen::Quaterniond::Identity(), s.q_WB);
        const double e = (s.p_W - p_d).norm();
        if (psi >= 1e-3)
          r.attitude_settled_s = -1;
        else if (r.attitude_settled_s < 0)
          r.attitude_settled_s = t;
        if (e >= 0.03)
          r.position_settled_s = -1;
        else if (r.position_settled_s < 0)
          r.position_settled_s = t;
        r.min_altitude_m = std::min(r.min_altitude_m, s.p_W.z());
        r.finite = r.finite && s.p_W.allFinite() && s.q_WB.coeffs().allFinite() && out.omega_rad_s.allFinite();
      });
  r.final_position_error_m = (x.p_W - p_d).norm();
  return r;
}

TEST(GeometricController, RecoversFromLargeAttitudeErrors) {
  // From rest at hover speed, 100 m up, turned by angle_deg about axis from the desired attitude (level,
  // yaw 0); the bounds [s] leave ~25 % over what the defaults reach. A yaw error is slow to remove: the
  // rotors' drag gives the Table 1 vehicle about 0.18 rad/s^2 of yaw acceleration at hover.
  struct Case {
    Eigen::Vector3d axis;
    double angle_deg;
    double attitude_bound_s, position_bound_s;
  };
  const std::vector<Case> cases = {{{1, 0, 0}, 170, 3.2, 4.8},
                                   {{0, 1, 0}, 170, 3.2, 4.8},
                                   {{1, 1, 0}, 170, 5.0, 4.8},
                                   {{1, -1, 1}, 150, 6.8, 4.4},
                                   {{0, 0, 1}, 170, 15.0, 0.5}};
  const double duration_s = 20.0;
  for (const Case& c : cases) {
    const Recovery r = recover(c.axis, c.angle_deg * kPi / 180.0, duration_s);
    std::printf(
        "recovery axis (%g, %g, %g) %g deg: Psi < 1e-3 from %.2f s, |e_x| < 3 cm from %.2f s, "
        "final |e_x| %.2e m, altitude lost %.2f m\n",
        c.axis.x(), c.axis.y(), c.axis.z(), c.angle_deg, r.attitude_settled_s, r.position_settled_s,
        r.final_position_error_m, 100.0 - r.min_altitude_m);
    EXPECT_TRUE(r.finite);
    EXPECT_GE(r.attitude_settled_s, 0.0) << c.axis.transpose() << " " << c.angle_deg;
    EXPECT_LE(r.attitude_settled_s, c.attitude_bound_s) << c.axis.transpose() << " " << c.angle_deg;
    EXPECT_GE(r.position_settled_s, 0.0) << c.axis.transpose() << " " << c.angle_deg;
    EXPECT_LE(r.position_settled_s, c.position_bound_s) << c.axis.transpose() << " " << c.angle_deg;
    EXPECT_LT(r.final_position_error_m, 0.01);
  }
}

// --- Circle tracking ------------------------------------------------------------------------------

struct Circle {
  double radius_m = 2.0, period_s = 10.0, altitude_m = 5.0;
  bool heading_follows = true;  ///< yaw along the velocity; else yaw 0
  double rate() const { return 2.0 * kPi / period_s; }
  /// Position, velocity, acceleration, jerk of (r cos wt, r sin wt, h), and the heading.
  Reference at(double t) const {
    const double w = rate(), c = std::cos(w * t), s = std::sin(w * t), r = radius_m;
    Reference ref;
    ref.mode = Mode::kPosition;
    ref.p_W = {r * c, r * s, altitude_m};
    ref.v_W = {-r * w * s, r * w * c, 0.0};
    ref.a_W = {-r * w * w * c, -r * w * w * s, 0.0};
    ref.j_W = {r * w * w * w * s, -r * w * w * w * c, 0.0};
    ref.yaw_rad = heading_follows ? model::wrap_pi(w * t + kPi / 2) : 0.0;
    ref.yaw_rate_rad_s = heading_follows ? w : 0.0;
    return ref;
  }
};

/// The attitude that points the thrust along a_W + g e3 with the body x axis at `yaw` (Lee's
/// construction, written out here independently of the controller).
Eigen::Matrix3d thrust_attitude(const Eigen::Vector3d& a_W, double g, double yaw) {
  const Eigen::Vector3d b3 = (a_W + g * Eigen::Vector3d::UnitZ()).normalized();
  const Eigen::Vector3d b2 = b3.cross(Eigen::Vector3d(std::cos(yaw), std::sin(yaw), 0)).normalized();
  Eigen::Matrix3d R;
  R << b2.cross(b3), b2, b3;
  return R;
}

TEST(GeometricController, FlatnessRatesMatchTheCircleRigidRotation) {
  // On the circle with the heading along the velocity, the whole desired configuration turns about
  // world z at w: R_d(t) = Rz(w t) R_d(0), so Omega_d = R_d^T (0, 0, w) exactly.
  const model::VehicleParams v;
  GeometricController ctl(v);
  const Circle circle;
  for (double t : {0.0, 1.3, 7.7}) {
    const Reference ref = circle.at(t);
    Observation obs;
    obs.p_W = ref.p_W;
    obs.v_W = ref.v_W;
    const Eigen::Matrix3d R_d = thrust_attitude(ref.a_W, v.gravity_m_s2, ref.yaw_rad);
    obs.q_WB = Eigen::Quaterniond(R_d);
    obs.w_B = R_d.transpose() * Eigen::Vector3d(0, 0, circle.rate());
    ControllerOutput out = new_output(ctl);
    ctl.step(obs, ref, kControlDt, out);
    EXPECT_LT((ctl.terms().R_d - R_d).norm(), 1e-12);
    EXPECT_LT((ctl.terms().Omega_d_B - obs.w_B).norm(), 1e-12) << ctl.terms().Omega_d_B.transpose();
    EXPECT_LT(ctl.terms().e_Omega_B.norm(), 1e-12);
    EXPECT_NEAR(out.U[0], v.mass_kg * (ref.a_W + v.gravity_m_s2 * Eigen::Vector3d::UnitZ()).norm(), 1e-9);
  }
}

struct CircleRun {
  double rmse_m = 0, max_m = 0;
  bool finite = true;
};

/// Flies three periods of `circle` on the plant with first-order motors; the RMSE and largest position
/// error over periods 2 and 3. `on_circle`: start in the reference state at t = 0 (position, velocity,
/// the attitude of a_d + g e3 at the reference heading, the body rates of that heading's turn, rotors
/// at the speed for that thrust); else at rest at hover at the circle's first point.
CircleRun fly_circle(const Circle& circle, bool on_circle, const model::VehicleParams& v = lagged_vehicle()) {
  const model::Quadrotor plant(v);
  GeometricController ctl(v);
  const Reference start = circle.at(0.0);
  model::State x = plant.initial_state(start.p_W, start.yaw_rad, /*hover=*/true);
  if (on_circle) {
    x.v_W = start.v_W;
    const Eigen::Matrix3d R0 = thrust_attitude(start.a_W, v.gravity_m_s2, start.yaw_rad);
    x.q_WB = Eigen::Quaterniond(R0);
    x.w_B = R0.transpose() * Eigen::Vector3d(0, 0, circle.heading_follows ? circle.rate() : 0.0);
    const double thrust = v.mass_kg * (start.a_W + v.gravity_m_s2 * Eigen::Vector3d::UnitZ()).norm();
    x.omega_rad_s.setConstant(std::sqrt(thrust / (4.0 * v.kt_N_per_rad2_s2)));
  }
  CircleRun run;
  double sum_sq = 0.0;
  int n = 0;
  const double periods = 3.0;
  fly(
      plant, ctl, x, periods * circle.period_s, [&](double t) { return circle.at(t); },
      [&](double t, const model::State& s, const ControllerOutput& out) {
        run.finite = run.finite && s.p_W.allFinite() && out.omega_rad_s.allFinite();
        if (t < circle.period_s) return;
        const double e = (s.p_W - circle.at(t).p_W).norm();
        sum_sq += e * e;
        run.max_m = std::max(run.max_m, e);
        ++n;
      });
  run.rmse_m = std::sqrt(sum_sq / n);
  std::printf(
      "circle r %.1f m, period %.0f s, heading %s, start %s: position RMSE over periods 2-3 %.3g mm, "
      "max %.3g mm\n",
      circle.radius_m, circle.period_s, circle.heading_follows ? "along the velocity" : "fixed",
      on_circle ? "on the circle" : "at rest", run.rmse_m * 1e3, run.max_m * 1e3);
  return run;
}

TEST(GeometricController, TracksACircle) {
  Circle circle;
  for (bool follows : {true, false}) {
    circle.heading_follows = follows;
    for (bool on_circle : {true, false}) {
      const CircleRun run = fly_circle(circle, on_circle);
      EXPECT_TRUE(run.finite);
      // The target is 5 cm; the defaults reach under 1 mm, so 5 mm still catches a lost feedforward.
      EXPECT_LT(run.rmse_m, 0.005) << "heading follows " << follows << ", on circle " << on_circle;
    }
  }
}

// Every ready vehicle, with the gains for_vehicle scales to it: recovers a hover from a 0.5 m offset
// and tracks the circle, starting at rest at its first point.
TEST(GeometricController, EveryPresetHoversAndTracksTheCircleWithItsScaledGains) {
  for (const model::VehiclePreset& preset : model::vehicle_presets()) {
    SCOPED_TRACE(std::string(preset.name));
    const model::VehicleParams& v = preset.params;
    const model::Quadrotor plant(v);
    GeometricController ctl(v);
    // The gains are the Table 1 design scaled by the vehicle: k_x / m and k_R / J_ii stay the same.
    const GeometricParams table1;
    EXPECT_NEAR(ctl.params().k_x.x() / v.mass_kg, table1.k_x.x() / 1.96, 1e-12);
    EXPECT_NEAR(ctl.params().k_Omega.z() / v.Izz_kg_m2, table1.k_Omega.z() / 0.0532, 1e-9);

    const Eigen::Vector3d p_d(0.0, 0.0, 10.0);
    model::State x = plant.initial_state(p_d + Eigen::Vector3d(0.5, -0.3, 0.2), 0.0, /*hover=*/true);
    bool finite = true;
    fly(
        plant, ctl, x, 8.0, [&](double) { return hold_position(p_d, 0.0); },
        [&](double, const model::State& s, const ControllerOutput& out) {
          finite = finite && s.p_W.allFinite() && out.omega_rad_s.allFinite();
        });
    EXPECT_TRUE(finite);
    EXPECT_LT((x.p_W - p_d).norm(), 0.01) << x.p_W.transpose();
    EXPECT_LT(x.v_W.norm(), 0.01);

    const CircleRun run = fly_circle(Circle{}, /*on_circle=*/false, v);
    EXPECT_TRUE(run.finite);
    // The tracking scenarios' specification is 5 cm RMSE and 10 cm at most; the presets reach 0.01 mm
    // or better (measured), so 1 mm still catches a gain scaled the wrong way.
    EXPECT_LT(run.rmse_m, 1e-3);
    EXPECT_LT(run.max_m, 2e-3);
  }
}

// --- 5. Parameters --------------------------------------------------------------------------------

TEST(GeometricController, ParametersAreCheckedAndRoundTrip) {
  GeometricController ctl(model::VehicleParams{});
  const std::vector<Setting> bad = {{"k_R.x", 2.0}, {"max_tilt", 4.0}};
  const std::string err = ctl.set_parameters(bad);
  EXPECT_NE(err.find("max_tilt"), std::string::npos) << err;
  EXPECT_EQ(std::get<double>(*ctl.get_parameter("k_R.x")), 1.49);  // all or nothing
  EXPECT_NE(ctl.set_parameters(std::vector<Setting>{{"k_v.z", -1.0}}).find("k_v.z"), std::string::npos);
  EXPECT_NE(ctl.set_parameters(std::vector<Setting>{{"k_q", 1.0}}).find("k_q"), std::string::npos);

  const std::vector<Setting> good = {{"k_x.y", 3.5}, {"k_Omega.z", 0.125}, {"max_tilt", 0.6}};
  EXPECT_EQ(ctl.set_parameters(good), "");
  EXPECT_EQ(std::get<double>(*ctl.get_parameter("k_x.y")), 3.5);
  EXPECT_EQ(std::get<double>(*ctl.get_parameter("k_Omega.z")), 0.125);
  EXPECT_EQ(std::get<double>(*ctl.get_parameter("max_tilt")), 0.6);
  EXPECT_EQ(ctl.params().k_x.y(), 3.5);
  EXPECT_FALSE(ctl.get_parameter("nope").has_value());
  // Every declared parameter reads back as what was set.
  for (const control::ParameterSpec& s : ctl.parameters()) {
    const double value = std::min(s.max, s.min + 0.25);
    ASSERT_EQ(ctl.set_parameters(std::vector<Setting>{{std::string(s.name), value}}), "") << s.name;
    EXPECT_EQ(std::get<double>(*ctl.get_parameter(s.name)), value) << s.name;
  }
  // A clone keeps them.
  const auto copy = ctl.clone();
  EXPECT_EQ(copy->type(), "se3");
  EXPECT_EQ(std::get<double>(*copy->get_parameter("min_cos_tilt")), 0.3);
}

TEST(GeometricController, TiltLimitCutsTheHorizontalForce) {
  const model::VehicleParams v;
  GeometricController ctl(v);
  ASSERT_EQ(ctl.set_parameters(std::vector<Setting>{{"max_tilt", 0.3}}), "");
  Observation obs;
  obs.p_W = {0, 0, 5};
  ControllerOutput out = new_output(ctl);
  ctl.step(obs, hold_position({20, 0, 5}, 0.0), kControlDt, out);  // far: F wants a steep tilt
  EXPECT_TRUE(out.tilt_saturated);
  const Eigen::Vector3d b3d = ctl.terms().R_d.col(2);
  EXPECT_NEAR(std::acos(b3d.z()), 0.3, 1e-12);
  EXPECT_GT(b3d.x(), 0.0);
  EXPECT_NEAR(b3d.y(), 0.0, 1e-15);
  EXPECT_NEAR(out.pitch_des_rad, 0.3, 1e-12);  // a nose-down pitch accelerates towards +x (FLU)
}

}  // namespace
}  // namespace quadcosim::controllers
