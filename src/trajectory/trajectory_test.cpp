// Tests of the reference trajectories: analytic derivatives against finite differences, closed forms
// of the circle and of rest-to-rest polynomials, smoothness and optimality of waypoint plans, and the
// polynomial file reader and writer.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <memory>
#include <numbers>
#include <string>
#include <vector>

#include "model/angle.hpp"
#include "trajectory/periodic.hpp"
#include "trajectory/polynomial_file.hpp"
#include "trajectory/waypoints.hpp"

namespace quadcosim::trajectory {
namespace {

constexpr double kPi = std::numbers::pi;

// Central differences with step h = 1e-5 s: truncation error h^2/6 |next derivative|, below 2e-7 for
// |next derivative| < 1e4 (the tangent yaw of a Lissajous curve turns fast at its tips), rounding
// eps |value| / h < 2e-9 for |value| < 100. Times closer
// than 2h to a point where a higher derivative jumps (start, end of spin-up, joins) are skipped.
void expect_derivatives_match_differences(const Trajectory& tr, double t0, double t1, std::vector<double> breaks) {
  const double h = 1e-5, tol = 1e-6;
  int checked = 0;
  for (double t = t0; t < t1; t += 0.0731) {
    bool near = false;
    for (double b : breaks) near = near || std::abs(t - b) < 2 * h;
    if (near) continue;
    const FlatOutput m = tr.at(t - h), c = tr.at(t), p = tr.at(t + h);
    for (int i = 0; i < 3; ++i) {
      EXPECT_NEAR(c.v_W[i], (p.p_W[i] - m.p_W[i]) / (2 * h), tol) << "velocity axis " << i << " t=" << t;
      EXPECT_NEAR(c.a_W[i], (p.v_W[i] - m.v_W[i]) / (2 * h), tol) << "acceleration axis " << i << " t=" << t;
      EXPECT_NEAR(c.j_W[i], (p.a_W[i] - m.a_W[i]) / (2 * h), tol) << "jerk axis " << i << " t=" << t;
    }
    EXPECT_NEAR(c.yaw_rate_rad_s, model::wrap_pi(p.yaw_rad - m.yaw_rad) / (2 * h), tol) << "yaw rate t=" << t;
    ++checked;
  }
  EXPECT_GT(checked, 50);
}

TEST(CircleTest, DerivativesMatchFiniteDifferencesForEveryYawMode) {
  for (YawMode mode : {YawMode::kFixed, YawMode::kTangent, YawMode::kCentre}) {
    for (bool cw : {false, true}) {
      CircleParams c;
      c.centre_m = {1.0, -2.0};
      c.altitude_m = 3.0;
      c.radius_m = 2.0;
      c.period_s = 6.0;
      c.clockwise = cw;
      c.phase_rad = 0.4;
      c.start_s = 1.0;
      c.ramp_s = 3.0;
      c.yaw_mode = mode;
      c.yaw_rad = 0.7;
      const auto tr = make_circle(c);
      expect_derivatives_match_differences(*tr, 0.0, 15.0, {1.0, 4.0});
    }
  }
}

TEST(CircleTest, RadiusSpeedAndPhaseFollowTheClosedForm) {
  CircleParams c;
  c.centre_m = {1.0, -2.0};
  c.altitude_m = 3.0;
  c.radius_m = 2.0;
  c.period_s = 8.0;
  c.phase_rad = 0.4;
  c.start_s = 1.0;
  c.ramp_s = 2.0;
  for (bool cw : {false, true}) {
    c.clockwise = cw;
    c.yaw_mode = YawMode::kTangent;
    const auto tangent = make_circle(c);
    c.yaw_mode = YawMode::kCentre;
    const auto centre = make_circle(c);
    const double sign = cw ? -1.0 : 1.0, w = 2 * kPi / 8.0;
    for (double t = 3.0; t < 30.0; t += 0.37) {  // after the spin-up: constant phase rate
      const FlatOutput o = tangent->at(t);
      const double theta = 0.4 + sign * w * (t - 1.0 - 1.0);  // lags the abrupt start by ramp_s / 2
      EXPECT_NEAR(o.p_W.x(), 1.0 + 2.0 * std::cos(theta), 1e-12);
      EXPECT_NEAR(o.p_W.y(), -2.0 + 2.0 * std::sin(theta), 1e-12);
      EXPECT_EQ(o.p_W.z(), 3.0);
      EXPECT_NEAR((o.p_W.head<2>() - Eigen::Vector2d(1.0, -2.0)).norm(), 2.0, 1e-12);
      EXPECT_NEAR(o.v_W.norm(), 2 * kPi * 2.0 / 8.0, 1e-12);
      EXPECT_NEAR(o.a_W.norm(), 4 * kPi * kPi * 2.0 / 64.0, 1e-12);
      EXPECT_NEAR(o.j_W.norm(), 2.0 * w * w * w, 1e-12);
      EXPECT_EQ(o.v_W.z(), 0.0);
      EXPECT_NEAR(model::wrap_pi(o.yaw_rad - (theta + sign * kPi / 2)), 0.0, 1e-12);
      EXPECT_NEAR(o.yaw_rate_rad_s, sign * w, 1e-12);
      const FlatOutput q = centre->at(t);
      EXPECT_NEAR(model::wrap_pi(q.yaw_rad - (theta + kPi)), 0.0, 1e-12);
      EXPECT_NEAR(q.yaw_rate_rad_s, sign * w, 1e-12);
    }
    // Before the start: the start point at rest; during the spin-up slower than the full speed.
    const FlatOutput before = tangent->at(0.5);
    EXPECT_NEAR(before.p_W.x(), 1.0 + 2.0 * std::cos(0.4), 1e-12);
    EXPECT_NEAR(before.p_W.y(), -2.0 + 2.0 * std::sin(0.4), 1e-12);
    EXPECT_EQ(before.v_W.norm() + before.a_W.norm() + before.j_W.norm() + before.yaw_rate_rad_s, 0.0);
    EXPECT_NEAR(model::wrap_pi(before.yaw_rad - (0.4 + sign * kPi / 2)), 0.0, 1e-12);
    EXPECT_LT(tangent->at(2.0).v_W.norm(), 2 * kPi * 2.0 / 8.0 * 0.99);
    EXPECT_TRUE(std::isinf(tangent->end_s()));
  }
}

TEST(CircleTest, AbruptStartJumpsToFullSpeed) {
  CircleParams c;
  c.radius_m = 1.0;
  c.period_s = 2 * kPi;  // 1 rad/s, speed 1 m/s
  c.start_s = 2.0;
  c.ramp_s = 0.0;
  const auto tr = make_circle(c);
  EXPECT_EQ(tr->at(1.999).v_W.norm(), 0.0);
  EXPECT_NEAR(tr->at(2.001).v_W.norm(), 1.0, 1e-12);
  EXPECT_NEAR(tr->at(2.0 + kPi / 2).p_W.y(), 1.0, 1e-12);  // a quarter lap ccw from (1, 0)
}

TEST(CircleTest, DescribeAndBadParameters) {
  CircleParams c;
  c.radius_m = 2;
  c.period_s = 10;
  c.altitude_m = 5;
  EXPECT_EQ(make_circle(c)->describe().rfind("circle r=2 m, period 10 s ccw about (0, 0) at 5 m", 0), 0u);
  c.radius_m = 0;
  EXPECT_THROW(make_circle(c), std::invalid_argument);
  c.radius_m = 1;
  c.ramp_s = -1;
  EXPECT_THROW(make_circle(c), std::invalid_argument);
}

TEST(LissajousTest, DerivativesMatchFiniteDifferencesAndTheClosedForm) {
  LissajousParams p;
  p.centre_m = {0.5, 0.25};
  p.altitude_m = 2.0;
  p.amplitude_m = {1.5, 0.8};
  p.period_s = {7.0, 3.0};
  p.phase_rad = {0.3, -1.1};
  p.start_s = 0.5;
  p.ramp_s = 1.5;
  for (YawMode mode : {YawMode::kFixed, YawMode::kTangent}) {
    p.yaw_mode = mode;
    const auto tr = make_lissajous(p);
    expect_derivatives_match_differences(*tr, 0.0, 20.0, {0.5, 2.0});
    for (double t = 2.5; t < 20; t += 0.77) {
      const double s = t - 0.5 - 0.75;
      const FlatOutput o = tr->at(t);
      EXPECT_NEAR(o.p_W.x(), 0.5 + 1.5 * std::sin(2 * kPi / 7.0 * s + 0.3), 1e-12);
      EXPECT_NEAR(o.p_W.y(), 0.25 + 0.8 * std::sin(2 * kPi / 3.0 * s - 1.1), 1e-12);
      EXPECT_NEAR(o.v_W.y(), 0.8 * 2 * kPi / 3.0 * std::cos(2 * kPi / 3.0 * s - 1.1), 1e-12);
      if (mode == YawMode::kTangent) {
        EXPECT_NEAR(model::wrap_pi(o.yaw_rad - std::atan2(o.v_W.y(), o.v_W.x())), 0, 1e-9);
      }
    }
  }
  p.yaw_mode = YawMode::kCentre;
  EXPECT_THROW(make_lissajous(p), std::invalid_argument);
}

TEST(Figure8Test, CrossesItsCentreEveryHalfPeriod) {
  Figure8Params p;
  p.centre_m = {1.0, 1.0};
  p.amplitude_m = {2.0, 1.0};
  p.period_s = 8.0;
  p.ramp_s = 2.0;
  p.yaw_mode = YawMode::kTangent;
  const auto tr = make_figure8(p);
  expect_derivatives_match_differences(*tr, 0.0, 20.0, {0.0, 2.0});
  for (int k = 1; k < 5; ++k) {  // s = t - 1 = 4 k
    const FlatOutput o = tr->at(1.0 + 4.0 * k);
    EXPECT_NEAR((o.p_W.head<2>() - Eigen::Vector2d(1.0, 1.0)).norm(), 0.0, 1e-12);
  }
  const FlatOutput top = tr->at(1.0 + 2.0);  // a quarter: x at +Ax, y at sin(pi) = 0
  EXPECT_NEAR(top.p_W.x(), 3.0, 1e-12);
  EXPECT_NEAR(top.p_W.y(), 1.0, 1e-12);
}

// ---------------------------------------------------------------------------------------------
// Waypoints

std::vector<Waypoint> mission() {
  return {{1.0, {0, 0, 1}, 0.0},
          {3.0, {2, 1, 1.5}, std::nullopt},
          {4.5, {3, -1, 2}, 3.0},
          {7.5, {0, -2, 1}, -3.0},
          {9.0, {-1, 0, 1}, std::nullopt}};
}

TEST(WaypointsTest, PassesThroughEveryWaypointAndDerivativesMatchDifferences) {
  for (WaypointMethod m : {WaypointMethod::kMinSnap, WaypointMethod::kMinJerk}) {
    const PiecewisePolynomial tr = plan_waypoints(mission(), m);
    EXPECT_EQ(tr.start_s(), 1.0);
    EXPECT_EQ(tr.end_s(), 9.0);
    for (const Waypoint& w : mission()) {
      EXPECT_LT((tr.at(w.t_s).p_W - w.p_W).norm(), 1e-9) << method_name(m) << " t=" << w.t_s;
    }
    expect_derivatives_match_differences(tr, 0.0, 10.0, {1.0, 3.0, 4.5, 7.5, 9.0});
  }
}

TEST(WaypointsTest, YawIsUnwrappedAndHeldWhereNotGiven) {
  const PiecewisePolynomial tr = plan_waypoints(mission(), WaypointMethod::kMinSnap);
  EXPECT_NEAR(tr.at(1.0).yaw_rad, 0.0, 1e-9);
  EXPECT_NEAR(tr.at(3.0).yaw_rad, 0.0, 1e-9);  // not given: the previous yaw
  EXPECT_NEAR(tr.at(4.5).yaw_rad, 3.0, 1e-9);
  EXPECT_NEAR(tr.at(7.5).yaw_rad, 3.0 + (2 * kPi - 6.0), 1e-9);  // -3 reached the short way round
  EXPECT_NEAR(tr.at(9.0).yaw_rad, 3.0 + (2 * kPi - 6.0), 1e-9);
  EXPECT_NEAR(tr.derivative(9.0, 1, true)[3], 0.0, 1e-9);
}

TEST(WaypointsTest, JoinsAreSmoothAndEndsAtRest) {
  const std::vector<double> joins = {3.0, 4.5, 7.5};
  for (WaypointMethod m : {WaypointMethod::kMinSnap, WaypointMethod::kMinJerk}) {
    const PiecewisePolynomial tr = plan_waypoints(mission(), m);
    const int smooth = m == WaypointMethod::kMinSnap ? 6 : 4, rest = m == WaypointMethod::kMinSnap ? 3 : 2;
    double highest_jump = 0;  // the first derivative that is not made continuous does jump
    for (double t : joins) {
      for (int r = 0; r <= smooth; ++r) {
        const Eigen::Vector4d l = tr.derivative(t, r, true), g = tr.derivative(t, r, false);
        EXPECT_LT((l - g).head<3>().norm(), 1e-8 * (1 + l.norm())) << method_name(m) << " t=" << t << " order " << r;
      }
      for (int r = 0; r <= 4; ++r) {  // yaw: minimum jerk, C^4
        EXPECT_NEAR(tr.derivative(t, r, true)[3], tr.derivative(t, r, false)[3], 1e-8) << "yaw order " << r;
      }
      highest_jump =
          std::max(highest_jump, (tr.derivative(t, smooth + 1, true) - tr.derivative(t, smooth + 1, false)).norm());
    }
    EXPECT_GT(highest_jump, 1e-3) << method_name(m);
    for (int r = 1; r <= rest; ++r) {
      EXPECT_LT(tr.derivative(1.0, r).head<3>().norm(), 1e-9) << "start, order " << r;
      EXPECT_LT(tr.derivative(9.0, r, true).head<3>().norm(), 1e-9) << "end, order " << r;
    }
    const FlatOutput after = tr.at(20.0), before = tr.at(0.0);
    EXPECT_LT((after.p_W - Eigen::Vector3d(-1, 0, 1)).norm(), 1e-12);
    EXPECT_EQ(after.v_W.norm() + after.a_W.norm() + after.j_W.norm(), 0.0);
    EXPECT_LT((before.p_W - Eigen::Vector3d(0, 0, 1)).norm(), 1e-12);
  }
}

TEST(WaypointsTest, RestToRestSegmentIsTheKnownClosedForm) {
  const Eigen::Vector3d a(1, 2, 3), b(-3, 4, 5);
  const double T = 4.0;
  const PiecewisePolynomial snap = plan_waypoints({{2.0, a, 0.0}, {2.0 + T, b, 1.0}}, WaypointMethod::kMinSnap);
  const PiecewisePolynomial jerk = plan_waypoints({{2.0, a, 0.0}, {2.0 + T, b, 1.0}}, WaypointMethod::kMinJerk);
  for (double s : {0.1, 0.25, 0.5, 0.8}) {
    const double s4 = std::pow(s, 4);
    const double snap_blend = 35 * s4 - 84 * s4 * s + 70 * s4 * s * s - 20 * s4 * s * s * s;
    const double jerk_blend = 10 * s * s * s - 15 * s4 + 6 * s4 * s;
    EXPECT_LT((snap.at(2.0 + s * T).p_W - (a + (b - a) * snap_blend)).norm(), 1e-12) << s;
    EXPECT_LT((jerk.at(2.0 + s * T).p_W - (a + (b - a) * jerk_blend)).norm(), 1e-12) << s;
    EXPECT_NEAR(snap.at(2.0 + s * T).yaw_rad, jerk_blend, 1e-12);  // yaw is minimum jerk
  }
  EXPECT_LT((snap.at(2.0 + T / 2).p_W - (a + b) / 2).norm(), 1e-12);
}

/// A polynomial in t by its coefficients (index = power), for building test variations.
using Poly = std::vector<double>;
Poly mul(const Poly& p, const Poly& q) {
  Poly r(p.size() + q.size() - 1, 0.0);
  for (std::size_t i = 0; i < p.size(); ++i)
    for (std::size_t j = 0; j < q.size(); ++j) r[i + j] += p[i] * q[j];
  return r;
}
Poly power(const Poly& p, int n) {
  Poly r = {1.0};
  for (int i = 0; i < n; ++i) r = mul(r, p);
  return r;
}
Poly differentiate(Poly p, int k) {
  for (int n = 0; n < k; ++n) {
    if (p.size() <= 1) return {0.0};
    Poly d(p.size() - 1);
    for (std::size_t i = 1; i < p.size(); ++i) d[i - 1] = p[i] * static_cast<double>(i);
    p = d;
  }
  return p;
}
double eval(const Poly& p, double t) {
  double r = 0;
  for (std::size_t i = p.size(); i-- > 0;) r = r * t + p[i];
  return r;
}

// Optimality, checked without the planner's own equations: add an admissible variation eta (zero at
// every waypoint, its derivatives 1..k-1 zero at both ends, C^(k-1) everywhere) to the x axis and
// integrate the cost (d^k x/dt^k)^2 numerically (composite Simpson, 2000 intervals per segment). At a
// minimum the first variation 2 <x^(k), eta^(k)> vanishes and J(+-eps) > J(0).
TEST(WaypointsTest, VariationsOnlyIncreaseTheCost) {
  const auto w = mission();
  for (WaypointMethod m : {WaypointMethod::kMinSnap, WaypointMethod::kMinJerk}) {
    const int k = m == WaypointMethod::kMinSnap ? 4 : 3;
    const PiecewisePolynomial tr = plan_waypoints(w, m);
    std::vector<std::pair<double, double>> ranges;  // support of each eta [s]
    std::vector<Poly> etas;
    // eta in the variable t - (start of its support), zero outside the support.
    for (std::size_t i = 0; i + 1 < w.size(); ++i) {  // a bump inside one segment
      const double b = w[i + 1].t_s - w[i].t_s;
      etas.push_back(mul(power({0.0, 1.0}, k), power({-b, 1.0}, k)));
      ranges.emplace_back(w[i].t_s, w[i + 1].t_s);
    }
    for (std::size_t i = 1; i + 1 < w.size(); ++i) {  // moves the free derivatives at waypoint i
      const double m = w[i].t_s - w[i - 1].t_s, b = w[i + 1].t_s - w[i - 1].t_s;
      etas.push_back(mul(mul(power({0.0, 1.0}, k), power({-b, 1.0}, k)), {-m, 1.0}));
      ranges.emplace_back(w[i - 1].t_s, w[i + 1].t_s);
    }
    for (std::size_t e = 0; e < etas.size(); ++e) {
      const Poly dk = differentiate(etas[e], k);
      // J(eps) = J0 + 2 eps cross + eps^2 eta2, each integral over the segments inside eta's support.
      double J0 = 0, cross = 0, eta2 = 0;
      for (std::size_t i = 0; i + 1 < w.size(); ++i) {
        const double a = w[i].t_s, b = w[i + 1].t_s;
        const int n = 2000;
        const double h = (b - a) / n;
        for (int j = 0; j <= n; ++j) {
          const double t = a + j * h;
          const double wgt = (j == 0 || j == n ? 1.0 : (j % 2 ? 4.0 : 2.0)) * h / 3.0;
          const double x = (j == n ? tr.derivative(t, k, true) : tr.derivative(t, k))[0];
          const bool inside = a >= ranges[e].first && b <= ranges[e].second;  // this segment
          const double y = inside ? eval(dk, t - ranges[e].first) : 0.0;
          J0 += wgt * x * x;
          cross += wgt * x * y;
          eta2 += wgt * y * y;
        }
      }
      EXPECT_LT(std::abs(cross), 1e-7 * std::sqrt(J0 * eta2)) << method_name(m) << " variation " << e;
      const double eps = 0.01 * std::sqrt(J0 / eta2);
      for (double s : {-eps, eps}) EXPECT_GT(J0 + 2 * s * cross + s * s * eta2, J0);
    }
  }
}

TEST(WaypointsTest, BadWaypointsAreRefused) {
  EXPECT_THROW(plan_waypoints({{0.0, {0, 0, 1}, {}}}, WaypointMethod::kMinSnap), std::invalid_argument);
  EXPECT_THROW(plan_waypoints({{1.0, {0, 0, 1}, {}}, {1.0, {1, 0, 1}, {}}}, WaypointMethod::kMinSnap),
               std::invalid_argument);
  EXPECT_THROW(plan_waypoints({{0.0, {0, 0, NAN}, {}}, {1.0, {1, 0, 1}, {}}}, WaypointMethod::kMinJerk),
               std::invalid_argument);
}

// ---------------------------------------------------------------------------------------------
// Polynomial files

class PolynomialFileTest : public ::testing::Test {
 protected:
  std::string write(const std::string& name, const std::string& text) {
    const std::string path = ::testing::TempDir() + "trajectory_test_" + name;
    std::ofstream(path, std::ios::binary) << text;
    return path;
  }
  static std::string header(bool upper = false) {
    std::string h = upper ? "DURATION" : "Duration";
    for (std::string axis : {"x", "y", "z", "yaw"}) {
      if (upper) axis = axis == "yaw" ? "YAW" : std::string(1, static_cast<char>(std::toupper(axis[0])));
      for (int i = 0; i < 8; ++i) h += "," + axis + "^" + std::to_string(i);
    }
    return h + "\n";
  }
  /// A row: duration then the 32 coefficients given (the rest zero).
  static std::string row(double duration, std::vector<std::pair<int, std::string>> set) {
    std::vector<std::string> f(33, "0");
    char buf[32];
    std::snprintf(buf, sizeof buf, "%g", duration);
    f[0] = buf;
    for (auto& [i, v] : set) f[static_cast<std::size_t>(i)] = v;
    std::string r;
    for (std::size_t i = 0; i < f.size(); ++i) r += (i ? "," : "") + f[i];
    return r + "\n";
  }
  std::string error_of(const std::string& name, const std::string& text) {
    const std::string path = write(name, text);
    try {
      read_polynomial_csv(path);
    } catch (const FileError& e) {
      const std::string msg = e.what();
      EXPECT_EQ(msg.rfind(path + ": ", 0), 0u) << msg;
      return msg;
    }
    ADD_FAILURE() << "no error for " << name;
    return "";
  }
};

TEST_F(PolynomialFileTest, HandWrittenCoefficientsGiveTheirValues) {
  // Segment 1 (2 s): x = 1 + 2 tau + 3 tau^2, y = tau^3, z = 0.5, yaw = 0.1 tau.
  // Segment 2 (1 s): x = 13 - tau, y = 8 + tau^2, z = 0.5 + tau^7, yaw = 0.2.
  // Columns: x^i = 1 + i, y^i = 9 + i, z^i = 17 + i, yaw^i = 25 + i.
  const std::string text = header(true) + row(2, {{1, "1"}, {2, "2"}, {3, "3"}, {12, "1"}, {17, "0.5"}, {26, "0.1"}}) +
                           "\n" +
                           row(1, {{1, "13"}, {2, "-1"}, {9, "8"}, {11, "1"}, {17, "0.5"}, {24, "1"}, {25, "0.2"}});
  const PiecewisePolynomial tr = read_polynomial_csv(write("hand.csv", text), 1.0);
  EXPECT_EQ(tr.end_s(), 4.0);
  const FlatOutput o = tr.at(1.5);  // tau = 0.5
  EXPECT_DOUBLE_EQ(o.p_W.x(), 2.75);
  EXPECT_DOUBLE_EQ(o.v_W.x(), 5.0);
  EXPECT_DOUBLE_EQ(o.a_W.x(), 6.0);
  EXPECT_DOUBLE_EQ(o.p_W.y(), 0.125);
  EXPECT_DOUBLE_EQ(o.v_W.y(), 0.75);
  EXPECT_DOUBLE_EQ(o.a_W.y(), 3.0);
  EXPECT_DOUBLE_EQ(o.j_W.y(), 6.0);
  EXPECT_DOUBLE_EQ(o.p_W.z(), 0.5);
  EXPECT_DOUBLE_EQ(o.yaw_rad, 0.05);
  EXPECT_DOUBLE_EQ(o.yaw_rate_rad_s, 0.1);
  const FlatOutput q = tr.at(3.5);  // segment 2, tau = 0.5
  EXPECT_DOUBLE_EQ(q.p_W.x(), 12.5);
  EXPECT_DOUBLE_EQ(q.v_W.x(), -1.0);
  EXPECT_DOUBLE_EQ(q.p_W.y(), 8.25);
  EXPECT_DOUBLE_EQ(q.p_W.z(), 0.5 + std::pow(0.5, 7));
  EXPECT_DOUBLE_EQ(q.j_W.z(), 210.0 * std::pow(0.5, 4));
  EXPECT_DOUBLE_EQ(q.yaw_rad, 0.2);
  const FlatOutput before = tr.at(0.0), after = tr.at(9.0);
  EXPECT_EQ(before.p_W, Eigen::Vector3d(1, 0, 0.5));
  EXPECT_EQ(before.v_W.norm(), 0.0);
  EXPECT_EQ(after.p_W, Eigen::Vector3d(12, 9, 1.5));
  EXPECT_EQ(after.v_W.norm() + after.a_W.norm() + after.j_W.norm(), 0.0);
}

TEST_F(PolynomialFileTest, MinSnapPlanRoundTripsThroughTheFile) {
  const PiecewisePolynomial plan = plan_waypoints(mission(), WaypointMethod::kMinSnap);
  const std::string path = ::testing::TempDir() + "trajectory_test_roundtrip.csv";
  write_polynomial_csv(path, plan);
  std::ifstream in(path);
  std::string first;
  std::getline(in, first);
  EXPECT_EQ(first + "\n", header());
  const PiecewisePolynomial back = read_polynomial_csv(path, plan.start_s());
  ASSERT_EQ(back.segments().size(), plan.segments().size());
  for (std::size_t i = 0; i < plan.segments().size(); ++i) {
    EXPECT_EQ(back.segments()[i].duration_s, plan.segments()[i].duration_s);
    EXPECT_EQ(back.segments()[i].c, plan.segments()[i].c);
  }
  for (double t = 0; t < 10; t += 0.3) {
    EXPECT_EQ(back.at(t).p_W, plan.at(t).p_W);
    EXPECT_EQ(back.at(t).j_W, plan.at(t).j_W);
  }
}

TEST_F(PolynomialFileTest, MalformedFilesNameLineAndProblem) {
  const std::string good = row(1, {{1, "1"}});
  EXPECT_NE(error_of("empty.csv", "").find("empty file"), std::string::npos);
  std::string bad_header = header();
  bad_header.replace(bad_header.find("x^2"), 3, "x^9");
  const std::string e1 = error_of("header.csv", bad_header + good);
  EXPECT_NE(e1.find("line 1: bad header: column 4 is 'x^9', expected 'x^2'"), std::string::npos) << e1;
  const std::string e2 = error_of("columns.csv", header() + good + "1,2,3\n");
  EXPECT_NE(e2.find("line 3: got 3 columns, expected 33"), std::string::npos) << e2;
  const std::string e3 = error_of("text.csv", header() + row(1, {{5, "abc"}}));
  EXPECT_NE(e3.find("line 2: column 6 (x^4): got 'abc', expected a number"), std::string::npos) << e3;
  const std::string e4 = error_of("nan.csv", header() + good + row(1, {{20, "nan"}}));
  EXPECT_NE(e4.find("line 3: column 21 (z^3): got 'nan', expected a finite number"), std::string::npos) << e4;
  const std::string e5 = error_of("duration.csv", header() + row(0, {}));
  EXPECT_NE(e5.find("line 2: Duration 0 s, expected a duration > 0"), std::string::npos) << e5;
  const std::string e6 = error_of("nosegment.csv", header());
  EXPECT_NE(e6.find("no segment"), std::string::npos) << e6;
  const std::string e7 = error_of("short_header.csv", "Duration,x^0\n" + good);
  EXPECT_NE(e7.find("line 1: got 2 columns, expected 33"), std::string::npos) << e7;
  try {
    read_polynomial_csv("/nonexistent/traj.csv");
    ADD_FAILURE() << "no error for a missing file";
  } catch (const FileError& e) {
    EXPECT_EQ(std::string(e.what()), "/nonexistent/traj.csv: cannot open the file");
  }
}

}  // namespace
}  // namespace quadcosim::trajectory
