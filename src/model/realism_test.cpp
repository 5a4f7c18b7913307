// Tests of the realism models against numbers they do not produce themselves: the statistics the
// noise generators are configured for, the Dryden spectra (estimated from long seeded series and
// compared with the published PSD and the autocorrelation it comes from), and closed-form drift in
// wind under linear and quadratic drag.
#include <gtest/gtest.h>

#include <cmath>
#include <complex>
#include <numbers>
#include <ostream>
#include <string>
#include <vector>

#include "model/quadrotor.hpp"
#include "model/random.hpp"
#include "model/sensor_noise.hpp"
#include "model/wind.hpp"

namespace quadcosim::model {
namespace {

struct Moments {
  double mean = 0.0, std = 0.0;
};
Moments moments(const std::vector<double>& x) {
  double s = 0.0, s2 = 0.0;
  for (double v : x) s += v;
  const double m = s / static_cast<double>(x.size());
  for (double v : x) s2 += (v - m) * (v - m);
  return {m, std::sqrt(s2 / static_cast<double>(x.size() - 1))};
}

TEST(RandomTest, NormalDeviatesHaveZeroMeanUnitVarianceAndNormalTails) {
  Rng rng(stream_seed(42, "/drone", "test"));
  const int n = 1'000'000;
  std::vector<double> x(n);
  int beyond2 = 0;
  for (double& v : x) {
    v = rng.normal();
    beyond2 += std::abs(v) > 2.0;
  }
  const Moments m = moments(x);
  EXPECT_NEAR(m.mean, 0.0, 5.0 / std::sqrt(n));  // 5 standard errors
  EXPECT_NEAR(m.std, 1.0, 5.0 / std::sqrt(2.0 * n));
  // P(|N| > 2) = erfc(2 / sqrt 2) = 0.0455
  EXPECT_NEAR(beyond2 / static_cast<double>(n), std::erfc(std::sqrt(2.0)), 0.001);
}

TEST(RandomTest, UniformsAreInsideTheOpenIntervalAndStreamsDiffer) {
  Rng a(stream_seed(1, "/drone", "imu.gyro")), b(stream_seed(1, "/drone", "imu.accel"));
  Rng c(stream_seed(1, "/uav2", "imu.gyro")), d(stream_seed(2, "/drone", "imu.gyro"));
  double lo = 1.0, hi = 0.0;
  int same = 0;
  for (int i = 0; i < 100000; ++i) {
    const double u = a.uniform();
    lo = std::min(lo, u);
    hi = std::max(hi, u);
    const std::uint64_t x = b.next_u64();
    same += x == c.next_u64() || x == d.next_u64();
  }
  EXPECT_GT(lo, 0.0);
  EXPECT_LT(hi, 1.0);
  EXPECT_LT(lo, 1e-4);
  EXPECT_GT(hi, 1.0 - 1e-4);
  EXPECT_EQ(same, 0);
  // Same seed, same numbers.
  Rng e(stream_seed(1, "/drone", "imu.gyro")), f(stream_seed(1, "/drone", "imu.gyro"));
  for (int i = 0; i < 1000; ++i) ASSERT_EQ(e.normal(), f.normal());
}

TEST(SensorNoiseTest, WhiteNoiseSigmaIsDensityTimesRootRate) {
  // 0.01 [unit/sqrt(Hz)] sampled at 400 Hz -> sigma 0.2 per sample.
  const double sigma = discrete_sigma(0.01, 400.0);
  EXPECT_DOUBLE_EQ(sigma, 0.2);
  Vector3Noise noise({sigma, 0.0, 0.0}, Rng(7));
  const int n = 200000;
  std::vector<double> x(n), y(n), z(n);
  const Eigen::Vector3d truth(1.0, -2.0, 3.0);
  for (int i = 0; i < n; ++i) {
    const Eigen::Vector3d s = noise.sample(truth);
    x[i] = s.x(), y[i] = s.y(), z[i] = s.z();
  }
  for (const auto* v : {&x, &y, &z}) {
    const Moments m = moments(*v);
    EXPECT_NEAR(m.std, 0.2, 0.2 * 5.0 / std::sqrt(2.0 * n));
  }
  EXPECT_NEAR(moments(x).mean, 1.0, 5 * 0.2 / std::sqrt(n));
  EXPECT_NEAR(moments(z).mean, 3.0, 5 * 0.2 / std::sqrt(n));
}

TEST(SensorNoiseTest, BiasRandomWalkVarianceGrowsLinearlyInTime) {
  // B = 0.002 [unit/sqrt(s)] at 100 Hz: after N samples Var(b) = N dt B^2 (+ the turn-on variance).
  const double B = 0.002, dt = 0.01, b0 = 0.003;
  const int N = 400, runs = 4000;
  std::vector<double> bias(runs), first(runs);
  for (int r = 0; r < runs; ++r) {
    Vector3Noise noise({0.0, bias_step_sigma(B, dt), b0}, Rng(stream_seed(r, "/drone", "walk")));
    first[r] = noise.bias().x();
    for (int i = 0; i < N; ++i) noise.sample(Eigen::Vector3d::Zero());
    bias[r] = noise.bias().x();
  }
  const double expected_var = b0 * b0 + N * dt * B * B;
  const Moments m = moments(bias);
  // The sample variance of 4000 normals has a relative standard error of sqrt(2/4000) = 2.2 %.
  EXPECT_NEAR(m.std * m.std, expected_var, 0.1 * expected_var);
  EXPECT_NEAR(moments(first).std, b0, 0.05 * b0);
  EXPECT_NEAR(m.mean, 0.0, 5.0 * std::sqrt(expected_var / runs));
}

TEST(SensorNoiseTest, AttitudeNoiseIsASmallRotationOfTheConfiguredSize) {
  Rng rng(3);
  const Eigen::Quaterniond q(Eigen::AngleAxisd(0.7, Eigen::Vector3d(1, 2, 3).normalized()));
  const int n = 50000;
  std::vector<double> ax(n);
  for (int i = 0; i < n; ++i) {
    const Eigen::Quaterniond e = q.conjugate() * perturb_attitude(q, 0.01, rng);  // body-frame error
    const Eigen::AngleAxisd aa(e);
    ax[i] = (aa.angle() * aa.axis()).x();
  }
  EXPECT_NEAR(moments(ax).std, 0.01, 0.01 * 5.0 / std::sqrt(2.0 * n));
  EXPECT_TRUE(perturb_attitude(q, 0.0, rng).isApprox(q, 0.0));
}

// --- Dryden --------------------------------------------------------------------------------------

TEST(DrydenTest, LowAltitudeScalesBecomeIsotropicAt1000Feet) {
  // MIL-F-8785C: at h = 1000 ft, 0.177 + 0.000823 h = 1, so L_u = L_v = L_w = h and sigma_u = sigma_w.
  GustParams p;
  p.enabled = true;
  p.altitude_m = 304.8;
  p.w20_m_s = 15.0;
  const DrydenScales s = dryden_low_altitude(p, 4.0);
  EXPECT_NEAR(s.L_u_m, 304.8, 1e-9);
  EXPECT_NEAR(s.L_w_m, 304.8, 1e-9);
  EXPECT_NEAR(s.sigma_u_m_s, 1.5, 1e-12);
  EXPECT_NEAR(s.sigma_w_m_s, 1.5, 1e-12);
  EXPECT_EQ(s.V_m_s, 4.0);
  // Below the model's 10 ft floor the scales stop shrinking.
  p.altitude_m = 1.0;
  EXPECT_NEAR(dryden_low_altitude(p, 0.0).L_w_m, 3.048, 1e-12);
  EXPECT_EQ(dryden_low_altitude(p, 0.0).V_m_s, 1.0);
}

TEST(DrydenTest, PublishedSpectraIntegrateToTheVariance) {
  // ∫0^∞ Φ dω = σ² (trapezoid on a log grid, independent of the closed forms).
  for (int form = 0; form < 2; ++form) {
    double sum = 0.0, w0 = 1e-6;
    for (int i = 1; i <= 200000; ++i) {
      const double w1 = 1e-6 * std::pow(10.0, i * 12.0 / 200000.0);  // 1e-6 .. 1e6 rad/s
      auto f = [&](double w) {
        return form == 0 ? dryden_psd_longitudinal(w, 2.0, 30.0, 5.0) : dryden_psd_lateral(w, 2.0, 30.0, 5.0);
      };
      sum += 0.5 * (f(w0) + f(w1)) * (w1 - w0);
      w0 = w1;
    }
    EXPECT_NEAR(sum, 4.0, 4.0 * 2e-3) << "form " << form;
  }
}

// One-sided PSD [unit²/Hz] at frequency f of the sampled process with autocorrelation R:
// G(f) = 2 T (R(0) + 2 Σ_{k≥1} R(kT) cos(2π f k T)), summed while the envelope e^{-V τ / L} > e^{-40}.
template <class R>
double sampled_psd(const R& r, double f, double T, double tau_max) {
  double s = r(0.0);
  for (int k = 1; k * T < tau_max; ++k) s += 2.0 * r(k * T) * std::cos(2.0 * std::numbers::pi * f * k * T);
  return 2.0 * T * s;
}

// Welch estimate (Hann window, 50 % overlap) of the one-sided PSD [unit²/Hz] at DFT bin `bin` of
// segments of length n.
double welch(const std::vector<double>& x, int n, int bin, double T) {
  std::vector<double> w(n);
  double w2 = 0.0;
  for (int i = 0; i < n; ++i) {
    w[i] = 0.5 - 0.5 * std::cos(2.0 * std::numbers::pi * i / n);
    w2 += w[i] * w[i];
  }
  std::vector<std::complex<double>> tw(n);
  for (int i = 0; i < n; ++i) tw[i] = std::polar(1.0, -2.0 * std::numbers::pi * bin * i / n);
  double acc = 0.0;
  int segments = 0;
  for (std::size_t start = 0; start + n <= x.size(); start += n / 2, ++segments) {
    std::complex<double> X = 0.0;
    for (int i = 0; i < n; ++i) X += w[i] * x[start + i] * tw[i];
    acc += 2.0 * T * std::norm(X) / w2;
  }
  return acc / segments;
}

struct DrydenCase {
  int order;
  double sigma, L, V;
};
// Printed in test names (instead of the raw bytes, padding included).
void PrintTo(const DrydenCase& c, std::ostream* os) {
  *os << (c.order == 1 ? "u" : "v") << " sigma " << c.sigma << " L " << c.L << " V " << c.V;
}

class DrydenSpectrumTest : public ::testing::TestWithParam<DrydenCase> {};

TEST_P(DrydenSpectrumTest, SeriesHasTheConfiguredMeanVarianceAndSpectrum) {
  const DrydenCase c = GetParam();
  const double T = 0.01;  // the plant's 100 Hz
  DrydenFilter f(c.order, c.sigma, c.L, c.V, T);
  Rng rng(stream_seed(11, "/drone", c.order == 1 ? "u" : "v"));
  f.start(rng);
  const int N = 1 << 20;  // 10486 s
  std::vector<double> x(N);
  for (int i = 0; i < N; ++i) {
    x[i] = f.value();
    f.advance(rng);
  }
  // Mean and variance: correlation time L / V = 2 s gives about 5000 independent samples, so the
  // standard errors are ~0.015 sigma (mean) and ~3 % (variance).
  const Moments m = moments(x);
  EXPECT_NEAR(m.mean, 0.0, 0.1 * c.sigma);
  EXPECT_NEAR(m.std * m.std, c.sigma * c.sigma, 0.1 * c.sigma * c.sigma);

  auto R = [&](double tau) {
    return c.order == 1 ? dryden_autocorrelation_longitudinal(tau, c.sigma, c.L, c.V)
                        : dryden_autocorrelation_lateral(tau, c.sigma, c.L, c.V);
  };
  auto Phi = [&](double w) {
    return c.order == 1 ? dryden_psd_longitudinal(w, c.sigma, c.L, c.V) : dryden_psd_lateral(w, c.sigma, c.L, c.V);
  };
  // Spectrum shape from 0.02 Hz (below the corner V / (2 π L) = 0.08 Hz) to 5 Hz: the Welch
  // estimate averaged over 7 neighbouring bins (255 segments each) has a relative standard error
  // of about 3 %; the bound is 15 %.
  const int n = 8192;
  const double df = 1.0 / (n * T);
  for (double f_hz : {0.02, 0.05, 0.1, 0.2, 0.5, 1.0, 2.0, 5.0}) {
    const int centre = static_cast<int>(std::lround(f_hz / df));
    double est = 0.0, exact = 0.0;
    for (int b = centre - 3; b <= centre + 3; ++b) {
      est += welch(x, n, b, T);
      exact += sampled_psd(R, b * df, T, 40.0 * c.L / c.V);
    }
    EXPECT_NEAR(est / exact, 1.0, 0.15) << "at " << f_hz << " Hz";
    // The published continuous PSD, per Hz (G = 2 π Φ(2 π f)): the sampled process matches it up to
    // aliasing, below 1 % up to 5 Hz at 100 Hz sampling.
    const double G = 2.0 * std::numbers::pi * Phi(2.0 * std::numbers::pi * centre * df);
    EXPECT_NEAR(sampled_psd(R, centre * df, T, 40.0 * c.L / c.V) / G, 1.0, 0.01) << "at " << f_hz << " Hz";
  }
}

INSTANTIATE_TEST_SUITE_P(Forms, DrydenSpectrumTest,
                         ::testing::Values(DrydenCase{1, 1.5, 20.0, 10.0}, DrydenCase{2, 0.8, 20.0, 10.0}),
                         [](const ::testing::TestParamInfo<DrydenCase>& i) {
                           return std::string(i.param.order == 1 ? "longitudinal" : "lateral");
                         });

TEST(WindFieldTest, MeanWindWithoutGustsAndGustsAlongTheWindAxes) {
  WindParams p;
  p.mean_W_m_s = {0.0, 4.0, 0.0};  // wind towards +y: u along y_W, v along -x_W
  WindField calm(p, 0.01, Rng(1));
  EXPECT_EQ(calm.at_tick(0), p.mean_W_m_s);
  EXPECT_EQ(calm.at_tick(500), p.mean_W_m_s);
  p.gusts.enabled = true;
  p.gusts.altitude_m = 50.0;
  WindField gusty(p, 0.01, Rng(stream_seed(5, "/drone", "wind.gusts")));
  const DrydenScales s = gusty.scales();
  const int N = 400000;
  std::vector<double> ex(N), ey(N), ez(N);
  for (int k = 0; k < N; ++k) {
    const Eigen::Vector3d w = gusty.at_tick(k);
    EXPECT_EQ(gusty.at_tick(k), w) << "asking again draws nothing";
    ex[k] = w.x(), ey[k] = w.y() - 4.0, ez[k] = w.z();
  }
  EXPECT_NEAR(moments(ey).std, s.sigma_u_m_s, 0.15 * s.sigma_u_m_s);  // longitudinal along y_W
  EXPECT_NEAR(moments(ex).std, s.sigma_v_m_s, 0.15 * s.sigma_v_m_s);
  EXPECT_NEAR(moments(ez).std, s.sigma_w_m_s, 0.15 * s.sigma_w_m_s);
  EXPECT_GT(s.sigma_u_m_s, s.sigma_w_m_s);  // below 1000 ft the horizontal gusts are the stronger
}

// --- Wind in the force balance -------------------------------------------------------------------

// A level vehicle whose thrust carries its weight, in a constant wind w along x with drag only.
struct DriftSetup {
  VehicleParams p;
  Environment env;
  State x;
  Vector4 cmd;
};
DriftSetup drift_setup(double lin, double quad, double w) {
  DriftSetup s;
  s.p.aero.linear_drag_N_s_m.setConstant(lin);
  s.p.aero.quadratic_drag_N_s2_m2.setConstant(quad);
  s.env.wind_W = {w, 0.0, 0.0};
  const Quadrotor q(s.p);
  s.x = q.initial_state({0.0, 0.0, 10.0}, 0.0, true);
  s.cmd = s.x.omega_rad_s;
  return s;
}

TEST(WindDragTest, LinearDragDriftFollowsTheClosedForm) {
  // m dv/dt = -d (v - w): v(t) = w (1 - exp(-d t / m)), x(t) = w (t - m/d (1 - exp(-d t / m))).
  const double d = 0.4, w = 3.0;
  DriftSetup s = drift_setup(d, 0.0, w);
  const Quadrotor q(s.p);
  const double m = s.p.mass_kg;
  for (int k = 1; k <= 2000; ++k) {
    q.step(s.x, (k - 1) * 0.01, s.cmd, 0.01, 1, &s.env);
    const double t = k * 0.01;
    const double e = std::exp(-d * t / m);
    ASSERT_NEAR(s.x.v_W.x(), w * (1.0 - e), 1e-10) << "t = " << t;
    ASSERT_NEAR(s.x.p_W.x(), w * (t - m / d * (1.0 - e)), 1e-9) << "t = " << t;
  }
  EXPECT_NEAR(s.x.p_W.z(), 10.0, 1e-9);  // thrust still balances weight: no vertical drift
  EXPECT_NEAR(s.x.v_W.y(), 0.0, 1e-12);
  EXPECT_NEAR(s.x.q_WB.angularDistance(Eigen::Quaterniond::Identity()), 0.0, 1e-12);
}

TEST(WindDragTest, QuadraticDragApproachesTheWindAsTheClosedFormSays) {
  // With u = w - v > 0: m du/dt = -c u², so u(t) = w / (1 + c w t / m).
  const double c = 0.1, w = 5.0;
  DriftSetup s = drift_setup(0.0, c, w);
  const Quadrotor q(s.p);
  const double m = s.p.mass_kg;
  for (int k = 1; k <= 2000; ++k) {
    q.step(s.x, (k - 1) * 0.01, s.cmd, 0.01, 1, &s.env);
    const double t = k * 0.01;
    ASSERT_NEAR(w - s.x.v_W.x(), w / (1.0 + c * w * t / m), 1e-9) << "t = " << t;
  }
}

TEST(WindDragTest, NoEnvironmentAndAnIdleEnvironmentGiveThePapersPlant) {
  // Zero coefficients, no wind, full efficiency: the environment path equals the plain one exactly.
  VehicleParams p;
  const Quadrotor q(p);
  State a = q.initial_state({0, 0, 5}, 0.3, true), b = a;
  const Vector4 cmd(4900.0, 4800.0, 4850.0, 4790.0);
  const Environment idle;
  for (int k = 0; k < 300; ++k) {
    q.step(a, k * 0.01, cmd, 0.01, 2);
    q.step(b, k * 0.01, cmd, 0.01, 2, &idle);
  }
  EXPECT_EQ(a.p_W, b.p_W);
  EXPECT_EQ(a.v_W, b.v_W);
  EXPECT_EQ(a.w_B, b.w_B);
  EXPECT_EQ(a.q_WB.coeffs(), b.q_WB.coeffs());
}

TEST(WindDragTest, RotorDragOpposesInPlaneAirspeedInProportionToRotorSpeed) {
  VehicleParams p;
  p.aero.rotor_drag_N_s_m_per_rad_s = 1e-5;
  const Vector4 omega = Vector4::Constant(5000.0);
  const Eigen::Vector3d F =
      aero_force_W(p.aero, Eigen::Matrix3d::Identity(), {2.0, -1.0, 3.0}, Eigen::Vector3d::Zero(), omega);
  EXPECT_NEAR(F.x(), -1e-5 * 20000.0 * 2.0, 1e-12);
  EXPECT_NEAR(F.y(), 1e-5 * 20000.0 * 1.0, 1e-12);
  EXPECT_EQ(F.z(), 0.0);  // no rotor drag along the rotor axis
}

TEST(RotorEfficiencyTest, ALostFractionOfThrustIsALostFractionOfGravityCompensation) {
  VehicleParams p;
  const Quadrotor q(p);
  const State x = q.initial_state({0, 0, 5}, 0.0, true);
  Environment env;
  env.rotor_efficiency.setConstant(0.5);
  const StateDerivative d = q.derivative(0.0, x, x.omega_rad_s, &env);
  EXPECT_NEAR(d.v_W.z(), -0.5 * p.gravity_m_s2, 1e-12);
  // One rotor at half efficiency: the thrust drops by 1/8 and the torque of the missing half-rotor
  // appears: rotor 1 sits on +x, so losing its lift pitches the nose down (positive pitch rate).
  env.rotor_efficiency = Vector4(0.5, 1.0, 1.0, 1.0);
  const StateDerivative d1 = q.derivative(0.0, x, x.omega_rad_s, &env);
  EXPECT_NEAR(d1.v_W.z(), -p.gravity_m_s2 / 8.0, 1e-12);
  const double lost_N = 0.5 * p.mass_kg * p.gravity_m_s2 / 4.0;
  EXPECT_NEAR(d1.w_B.y(), lost_N * p.arm_length_m / p.Iyy_kg_m2, 1e-9);
}

TEST(GroundEffectTest, CheesemanBennettFactor) {
  AeroParams a;
  EXPECT_EQ(ground_effect_factor(a, 0.1), 1.0);  // off
  a.ground_effect_rotor_radius_m = 0.2;
  EXPECT_NEAR(ground_effect_factor(a, 0.2), 16.0 / 15.0, 1e-15);  // z = R
  EXPECT_NEAR(ground_effect_factor(a, 0.0), 4.0 / 3.0, 1e-15);    // floored at z = R/2
  EXPECT_NEAR(ground_effect_factor(a, 100.0), 1.0, 1e-6);
}

}  // namespace
}  // namespace quadcosim::model
