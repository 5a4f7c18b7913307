// Tests of the step-response figures against responses whose figures are known in closed form
// (second-order underdamped, first-order), sampled at 100 Hz as the recorder samples the plant.
#include "analysis/step_metrics.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <functional>
#include <numbers>
#include <optional>
#include <span>
#include <string>
#include <vector>

namespace quadcosim::analysis {
namespace {

constexpr double kRateHz = 100.0;
constexpr double kDt = 1.0 / kRateHz;  // one sample [s]
constexpr double kPi = std::numbers::pi;

/// Unit step response of wn^2 / (s^2 + 2 zeta wn s + wn^2), 0 < zeta < 1, at time tau >= 0 after the step.
double second_order(double zeta, double wn, double tau) {
  const double root = std::sqrt(1.0 - zeta * zeta);
  const double wd = wn * root;
  return 1.0 - std::exp(-zeta * wn * tau) * (std::cos(wd * tau) + zeta / root * std::sin(wd * tau));
}

/// Unit step response of 1 / (T s + 1).
double first_order(double T, double tau) { return 1.0 - std::exp(-tau / T); }

/// A sampled signal: t_k = k / rate (computed, not summed); y = y0 before t_step (or `before(t)` when
/// given) and y0 + (target - y0) * unit(t - t_step) from t_step on.
struct Sampled {
  std::vector<double> t, y;
};
Sampled sample(double duration_s, double t_step, double y0, double target, const std::function<double(double)>& unit,
               const std::function<double(double)>& before = nullptr) {
  Sampled s;
  const auto n = static_cast<int>(std::lround(duration_s * kRateHz));
  for (int k = 0; k <= n; ++k) {
    const double t = k / kRateHz;
    s.t.push_back(t);
    if (t < t_step) {
      s.y.push_back(before ? before(t) : y0);
    } else {
      s.y.push_back(y0 + (target - y0) * unit(t - t_step));
    }
  }
  return s;
}

/// Brute-force 2 % settling time of a unit response on a fine grid: the first grid time after the
/// last one at which |y - 1| exceeds the band.
double brute_force_settling(const std::function<double(double)>& unit, double duration_s, double band = 0.02,
                            double h = 1e-5) {
  const auto n = static_cast<long>(std::lround(duration_s / h));
  long last_out = -1;
  for (long i = 0; i <= n; ++i) {
    if (std::abs(unit(static_cast<double>(i) * h) - 1.0) > band) last_out = i;
  }
  return static_cast<double>(last_out + 1) * h;
}

/// Brute-force first time the unit response reaches `level`, on a fine grid.
double brute_force_first_reach(const std::function<double(double)>& unit, double level, double duration_s,
                               double h = 1e-5) {
  const auto n = static_cast<long>(std::lround(duration_s / h));
  for (long i = 0; i <= n; ++i) {
    if (unit(static_cast<double>(i) * h) >= level) return static_cast<double>(i) * h;
  }
  return std::nan("");
}

/// Value at `tau` after a first-order step of size 2 from 1 with time constant T (for the up-and-down case).
double v_at(double /*t_step*/, double T, double tau) { return 1.0 + 2.0 * first_order(T, tau); }

StepFigures figures_of(const Sampled& s, double t_step, double target, const StepOptions& opt = {}) {
  return step_figures(s.t, s.y, t_step, target, opt);
}

struct SecondOrderCase {
  double zeta, wn;
};

class SecondOrderTest : public ::testing::TestWithParam<SecondOrderCase> {};

// Checks the figures of a second-order step however it is placed: from y0 to target at t_step.
void expect_second_order_figures(double zeta, double wn, double t_step, double y0, double target) {
  SCOPED_TRACE(testing::Message() << "zeta " << zeta << ", wn " << wn << ", step at " << t_step << " s from " << y0
                                  << " to " << target);
  const double duration = t_step + 12.0;
  const auto unit = [&](double tau) { return second_order(zeta, wn, tau); };
  const Sampled s = sample(duration, t_step, y0, target, unit);
  const StepFigures f = figures_of(s, t_step, target);

  const double root = std::sqrt(1.0 - zeta * zeta);
  const double wd = wn * root;
  EXPECT_DOUBLE_EQ(f.initial, y0);
  EXPECT_DOUBLE_EQ(f.target, target);

  // Overshoot: the sampled peak lies within half a sample of the true one, where y' = 0, so it falls
  // short by at most 1/2 max|y''| (dt/2)^2, and |y''| <= wn^2 / sqrt(1 - zeta^2).
  const double overshoot = std::exp(-kPi * zeta / root) * 100.0;
  const double tol_pct = 0.5 * wn * wn / root * (kDt / 2) * (kDt / 2) * 100.0 + 1e-9;
  ASSERT_TRUE(f.overshoot_pct.has_value());
  EXPECT_LE(*f.overshoot_pct, overshoot + 1e-9);
  EXPECT_GE(*f.overshoot_pct, overshoot - tol_pct);

  ASSERT_TRUE(f.peak_time_s.has_value());
  EXPECT_NEAR(*f.peak_time_s, kPi / wd, kDt + 1e-9);

  ASSERT_TRUE(f.settling_time_2pct_s.has_value());
  EXPECT_NEAR(*f.settling_time_2pct_s, brute_force_settling(unit, duration - t_step), kDt + 1e-9);

  ASSERT_TRUE(f.t95_s.has_value());
  EXPECT_NEAR(*f.t95_s, brute_force_first_reach(unit, 0.95, duration - t_step), kDt + 1e-9);

  ASSERT_TRUE(f.rise_time_s.has_value());
  const double rise =
      brute_force_first_reach(unit, 0.90, duration - t_step) - brute_force_first_reach(unit, 0.10, duration - t_step);
  EXPECT_NEAR(*f.rise_time_s, rise, kDt + 1e-9);

  // The 2 % settling time lies within the envelope bound: |y - 1| <= e^{-zeta wn tau} / sqrt(1 - zeta^2),
  // which is inside the band from tau = ln(1 / (0.02 sqrt(1 - zeta^2))) / (zeta wn) on.
  EXPECT_LE(*f.settling_time_2pct_s, std::log(1.0 / (0.02 * root)) / (zeta * wn) + kDt + 1e-9);
  EXPECT_EQ(f.verdict, StepVerdict::kSettled);

  // The final window is the last 10 % of the 12 s after the step (1.2 s, more than the 1 s minimum);
  // over it the residual oscillation is below its envelope.
  EXPECT_DOUBLE_EQ(f.final_window_s, 0.1 * (duration - t_step));
  ASSERT_TRUE(f.steady_state_error_pct.has_value());
  EXPECT_GE(*f.steady_state_error_pct, 0.0);
  EXPECT_LE(*f.steady_state_error_pct, std::exp(-zeta * wn * (duration - t_step - 1.2)) / root * 100.0 + 1e-9);
}

TEST_P(SecondOrderTest, FiguresMatchTheAnalyticResponse) {
  const auto [zeta, wn] = GetParam();
  expect_second_order_figures(zeta, wn, 0.0, 0.0, 1.0);
}

TEST_P(SecondOrderTest, StepLaterAndFromAnOffsetGivesTheSameFigures) {
  const auto [zeta, wn] = GetParam();
  expect_second_order_figures(zeta, wn, 2.0, 3.0, 7.5);
  expect_second_order_figures(zeta, wn, 1.37, -4.0, 10.0);
}

TEST_P(SecondOrderTest, NegativeStepGivesTheSameFigures) {
  const auto [zeta, wn] = GetParam();
  expect_second_order_figures(zeta, wn, 0.0, 1.0, 0.0);
  expect_second_order_figures(zeta, wn, 2.5, 3.0, 1.0);
}

INSTANTIATE_TEST_SUITE_P(Underdamped, SecondOrderTest,
                         ::testing::Values(SecondOrderCase{0.5, 4.0}, SecondOrderCase{0.3, 2.5},
                                           SecondOrderCase{0.7, 3.0}, SecondOrderCase{0.59, 1.3}));

TEST(StepFiguresTest, SamplesBeforeTheStepAreIgnored) {
  const auto unit = [](double tau) { return second_order(0.5, 4.0, tau); };
  // Wild values before the step must change nothing: not the peak, not the initial value.
  const Sampled s = sample(14.0, 2.0, 3.0, 1.0, unit, [](double t) { return 100.0 * std::sin(7.0 * t); });
  const Sampled clean = sample(14.0, 2.0, 3.0, 1.0, unit);
  const StepFigures f = figures_of(s, 2.0, 1.0);
  const StepFigures g = figures_of(clean, 2.0, 1.0);
  EXPECT_EQ(f.initial, 3.0);
  EXPECT_EQ(f.overshoot_pct, g.overshoot_pct);
  EXPECT_EQ(f.peak_time_s, g.peak_time_s);
  EXPECT_EQ(f.rise_time_s, g.rise_time_s);
  EXPECT_EQ(f.t95_s, g.t95_s);
  EXPECT_EQ(f.settling_time_2pct_s, g.settling_time_2pct_s);
  EXPECT_EQ(f.steady_state_error_pct, g.steady_state_error_pct);
}

TEST(StepFiguresTest, StepBetweenSamplesMeasuresFromTheStepInstant) {
  // The step at 1.005 s falls between samples; the first analysed sample is at 1.01 s, where the
  // response is already under way. Times are still counted from 1.005 s.
  const double t_step = 1.005;
  const auto unit = [](double tau) { return first_order(0.5, tau); };
  const Sampled s = sample(11.0, t_step, 0.0, 1.0, unit);
  const StepFigures f = figures_of(s, t_step, 1.0);
  EXPECT_NEAR(f.initial, first_order(0.5, 0.005), 1e-12);
  ASSERT_TRUE(f.t95_s.has_value());
  // 95 % of the step from y(1.01 s) is a little later than 95 % of the unit step.
  EXPECT_GE(*f.t95_s, 0.5 * std::log(20.0));
  EXPECT_LE(*f.t95_s, 0.5 * std::log(20.0) + 2 * kDt);
}

TEST(StepFiguresTest, FirstOrderResponse) {
  for (const double T : {0.1, 0.5, 1.23}) {
    SCOPED_TRACE(testing::Message() << "time constant " << T);
    const auto unit = [T](double tau) { return first_order(T, tau); };
    const double duration = 25.0 * T + 1.5;
    const Sampled s = sample(duration, 0.0, 0.0, 1.0, unit);
    const StepFigures f = figures_of(s, 0.0, 1.0);

    // Each level is reached at the first sample at or after its analytic time.
    ASSERT_TRUE(f.t95_s.has_value());
    EXPECT_GE(*f.t95_s, T * std::log(20.0) - 1e-12);  // = 2.996 T, the "3 T" of textbooks
    EXPECT_LT(*f.t95_s, T * std::log(20.0) + kDt);
    EXPECT_NEAR(*f.t95_s, 3.0 * T, 0.005 * T + kDt);

    ASSERT_TRUE(f.rise_time_s.has_value());
    EXPECT_NEAR(*f.rise_time_s, T * std::log(9.0), kDt + 1e-12);

    ASSERT_TRUE(f.settling_time_2pct_s.has_value());
    EXPECT_NEAR(*f.settling_time_2pct_s, T * std::log(50.0), kDt + 1e-12);

    ASSERT_TRUE(f.overshoot_pct.has_value());
    EXPECT_EQ(*f.overshoot_pct, 0.0);
    EXPECT_FALSE(f.peak_time_s.has_value());

    ASSERT_TRUE(f.steady_state_error_pct.has_value());
    EXPECT_NEAR(*f.steady_state_error_pct, 0.0, 1e-6);
  }
}

TEST(StepFiguresTest, NegativeFirstOrderStepFromAnOffset) {
  const double T = 0.4;
  const auto unit = [T](double tau) { return first_order(T, tau); };
  const Sampled s = sample(15.0, 3.0, 5.0, -2.0, unit);
  const StepFigures f = figures_of(s, 3.0, -2.0);
  EXPECT_EQ(f.initial, 5.0);
  EXPECT_EQ(f.target, -2.0);
  ASSERT_TRUE(f.t95_s.has_value());
  EXPECT_GE(*f.t95_s, T * std::log(20.0) - 1e-9);
  EXPECT_LT(*f.t95_s, T * std::log(20.0) + kDt + 1e-9);
  ASSERT_TRUE(f.rise_time_s.has_value());
  EXPECT_NEAR(*f.rise_time_s, T * std::log(9.0), kDt + 1e-9);
  ASSERT_TRUE(f.settling_time_2pct_s.has_value());
  EXPECT_NEAR(*f.settling_time_2pct_s, T * std::log(50.0), kDt + 1e-9);
  EXPECT_EQ(f.overshoot_pct, 0.0);
  EXPECT_FALSE(f.peak_time_s.has_value());
  ASSERT_TRUE(f.steady_state_error_pct.has_value());
  EXPECT_NEAR(*f.steady_state_error_pct, 0.0, 1e-6);
}

TEST(StepFiguresTest, ResponseThatNeverSettles) {
  // Undamped oscillation between 0 and 2 around the target 1: never within 2 %.
  const auto unit = [](double tau) { return 1.0 - std::cos(kPi * tau); };
  const Sampled s = sample(10.0, 0.0, 0.0, 1.0, unit);
  const StepFigures f = figures_of(s, 0.0, 1.0);
  EXPECT_FALSE(f.settling_time_2pct_s.has_value());
  ASSERT_TRUE(f.overshoot_pct.has_value());
  EXPECT_NEAR(*f.overshoot_pct, 100.0, 1e-9);
  ASSERT_TRUE(f.peak_time_s.has_value());
  EXPECT_NEAR(*f.peak_time_s, 1.0, 1e-9);  // the first peak, not a later equal one
}

TEST(StepFiguresTest, ResponseThatStopsShortHasNoSettlingAndAKnownError) {
  // Converges to 85 % of the step: never reaches 90 % or 95 %, never settles, 15 % steady-state error.
  const auto unit = [](double tau) { return 0.85 * first_order(0.3, tau); };
  const Sampled s = sample(10.0, 0.0, 2.0, 4.0, unit);
  const StepFigures f = figures_of(s, 0.0, 4.0);
  EXPECT_FALSE(f.t95_s.has_value());
  EXPECT_FALSE(f.settling_time_2pct_s.has_value());
  EXPECT_FALSE(f.peak_time_s.has_value());
  EXPECT_EQ(f.overshoot_pct, 0.0);
  EXPECT_FALSE(f.rise_time_s.has_value());  // 90 % is never reached
  ASSERT_TRUE(f.steady_state_error_pct.has_value());
  EXPECT_NEAR(*f.steady_state_error_pct, 15.0, 1e-6);
}

TEST(StepFiguresTest, SteadyStateErrorFromAKnownOffset) {
  // Settles 0.1 above the target 4 after a step of size 2 from 2: 5 % of the step.
  const auto unit = [](double tau) { return 1.05 * first_order(0.2, tau); };
  const Sampled s = sample(12.0, 1.0, 2.0, 4.0, unit);
  const StepFigures f = figures_of(s, 1.0, 4.0);
  ASSERT_TRUE(f.steady_state_error_pct.has_value());
  EXPECT_NEAR(*f.steady_state_error_pct, 5.0, 1e-6);
  ASSERT_TRUE(f.overshoot_pct.has_value());
  EXPECT_NEAR(*f.overshoot_pct, 5.0, 1e-6);
  // Settled within 2 % of the step means within [3.96, 4.04]: never, it stays at 4.1.
  EXPECT_FALSE(f.settling_time_2pct_s.has_value());

  // The same offset below a negative step: target -1 from 1, final value -0.96 (2 % of 2 short).
  const auto low = [](double tau) { return 0.98 * first_order(0.2, tau); };
  const Sampled n = sample(12.0, 0.0, 1.0, -1.0, low);
  const StepFigures g = figures_of(n, 0.0, -1.0);
  ASSERT_TRUE(g.steady_state_error_pct.has_value());
  EXPECT_NEAR(*g.steady_state_error_pct, 2.0, 1e-6);
}

TEST(StepFiguresTest, SteadyStateErrorAveragesOverTheFinalWindow) {
  // A constant offset of +0.2 in the last 0.5 s only: a 0.5 s window sees all of it, a 1 s window half.
  std::vector<double> t, y;
  for (int k = 0; k <= 1000; ++k) {
    t.push_back(k / kRateHz);
    y.push_back(k == 0 ? 0.0 : (t.back() > 9.5 + 1e-9 ? 1.2 : 1.0));
  }
  StepOptions half;
  half.final_window_fraction = 0.0;
  half.final_window_min_s = 0.5 - 1e-9;  // t > 9.5: exactly the 50 raised samples
  const StepFigures f = step_figures(t, y, 0.0, 1.0, half);
  ASSERT_TRUE(f.steady_state_error_pct.has_value());
  EXPECT_NEAR(*f.steady_state_error_pct, 20.0, 1e-9);
  const StepFigures g = step_figures(t, y, 0.0, 1.0);  // the last 1 s: 101 samples, 50 raised
  ASSERT_TRUE(g.steady_state_error_pct.has_value());
  EXPECT_NEAR(*g.steady_state_error_pct, 20.0 * 50.0 / 101.0, 1e-9);
}

void expect_all_empty(const StepFigures& f) {
  for (const auto& name : figure_names()) {
    EXPECT_FALSE(figure(f, name).has_value()) << name;
  }
}

TEST(StepFiguresTest, ZeroStepSizeGivesEmptyFigures) {
  const Sampled s = sample(5.0, 1.0, 2.0, 2.0, [](double tau) { return first_order(0.3, tau); });
  const StepFigures f = figures_of(s, 1.0, 2.0);
  EXPECT_EQ(f.initial, 2.0);
  EXPECT_EQ(f.target, 2.0);
  expect_all_empty(f);
}

TEST(StepFiguresTest, TooFewSamplesOrMismatchedLengthsGiveEmptyFigures) {
  const std::vector<double> t = {0.0, 0.01, 0.02}, y = {0.0, 0.5, 1.0}, y_short = {0.0, 0.5};
  expect_all_empty(step_figures(t, y, 0.02, 1.0));  // one sample after the step
  expect_all_empty(step_figures(t, y, 0.5, 1.0));   // none
  expect_all_empty(step_figures(t, y_short, 0.0, 1.0));
  expect_all_empty(step_figures({}, {}, 0.0, 1.0));
}

TEST(StepFiguresTest, FigureLooksUpEveryNameAndRejectsUnknownOnes) {
  StepFigures f;
  f.overshoot_pct = 1.0;
  f.peak_time_s = 2.0;
  f.rise_time_s = 3.0;
  f.t95_s = 4.0;
  f.settling_time_2pct_s = 5.0;
  f.steady_state_error_pct = 6.0;
  const std::vector<std::string> expected = {"overshoot_pct", "peak_time_s",          "rise_time_s",
                                             "t95_s",         "settling_time_2pct_s", "steady_state_error_pct"};
  ASSERT_EQ(figure_names(), expected);
  for (std::size_t i = 0; i < expected.size(); ++i) {
    EXPECT_EQ(figure(f, expected[i]), static_cast<double>(i + 1)) << expected[i];
  }
  EXPECT_FALSE(figure(f, "overshoot").has_value());
  EXPECT_FALSE(figure(f, "").has_value());
}

// --- The verdict: settled, not settled, too short, zero-size step -------------------------------

TEST(StepVerdictTest, ARunThatEndsStillClimbingIsNotSettled) {
  // 0 -> 2 m, first order with T = 1.4 s, stopped 1.65 s after the step: y(1.65) = 2 (1 - e^{-1.65/1.4})
  // = 1.38 m, still climbing at 0.44 m/s. The final window is the 1 s minimum (10 % of 1.65 s is less).
  const double T = 1.4;
  const Sampled s = sample(1.65, 0.0, 0.0, 2.0, [T](double tau) { return first_order(T, tau); });
  const StepFigures f = figures_of(s, 0.0, 2.0);
  EXPECT_EQ(f.verdict, StepVerdict::kNotSettled);
  EXPECT_DOUBLE_EQ(f.final_window_s, 1.0);
  EXPECT_FALSE(f.settling_time_2pct_s.has_value());
  // The mean of 1 - e^{-tau/T} over tau in [0.65, 1.65] s (101 samples), against the target 1.
  double mean = 0.0;
  for (int k = 65; k <= 165; ++k) mean += first_order(T, k * kDt);
  mean /= 101.0;
  ASSERT_TRUE(f.steady_state_error_pct.has_value());
  EXPECT_NEAR(*f.steady_state_error_pct, (1.0 - mean) * 100.0, 1e-9);
  EXPECT_GT(*f.steady_state_error_pct, 40.0);
  const std::string why = unjudgeable_reason(f, "settling_time_2pct_s");
  EXPECT_NE(why.find("ended before settling"), std::string::npos) << why;
  EXPECT_NE(unjudgeable_reason(f, "steady_state_error_pct").find("ended before settling"), std::string::npos);
  EXPECT_EQ(unjudgeable_reason(f, "t95_s"), "");  // reached or not, t95 is what happened
}

TEST(StepVerdictTest, InsideTheBandAtTheLastSampleIsNotEnough) {
  // A ramp that arrives at the target exactly at the end: the last sample is on target, but the
  // final second is not inside the band, so it has not settled.
  std::vector<double> t, y;
  for (int k = 0; k <= 500; ++k) {
    t.push_back(k * kDt);
    y.push_back(k / 500.0);
  }
  const StepFigures f = step_figures(t, y, 0.0, 1.0);
  EXPECT_EQ(f.verdict, StepVerdict::kNotSettled);
  EXPECT_FALSE(f.settling_time_2pct_s.has_value());
  // Enters the band (y >= 0.98) at 4.90 s and stays: settled once the final window is short enough
  // to lie after it (window of 0.05 s: t >= 4.95 s).
  StepOptions tiny;
  tiny.final_window_fraction = 0.0;
  tiny.final_window_min_s = 0.05;
  const StepFigures g = step_figures(t, y, 0.0, 1.0, tiny);
  EXPECT_EQ(g.verdict, StepVerdict::kSettled);
  ASSERT_TRUE(g.settling_time_2pct_s.has_value());
  EXPECT_NEAR(*g.settling_time_2pct_s, 4.90, kDt + 1e-9);  // 490/500 is 0.98 only to rounding
}

TEST(StepVerdictTest, LeavingTheBandAgainInTheFinalWindowIsNotSettled) {
  // Settled first order, then a disturbance of 5 % of the step in the last 0.3 s.
  const auto unit = [](double tau) { return first_order(0.3, tau) + (tau > 9.7 ? 0.05 : 0.0); };
  const Sampled s = sample(10.0, 0.0, 0.0, 1.0, unit);
  const StepFigures f = figures_of(s, 0.0, 1.0);
  EXPECT_EQ(f.verdict, StepVerdict::kNotSettled);
  EXPECT_FALSE(f.settling_time_2pct_s.has_value());
}

TEST(StepVerdictTest, ARunTooShortToJudge) {
  // 0.8 s after the step: the 1 s final window does not fit.
  const Sampled s = sample(0.8, 0.0, 0.0, 1.0, [](double tau) { return first_order(0.1, tau); });
  const StepFigures f = figures_of(s, 0.0, 1.0);
  EXPECT_EQ(f.verdict, StepVerdict::kTooShort);
  EXPECT_FALSE(f.settling_time_2pct_s.has_value());
  EXPECT_FALSE(f.steady_state_error_pct.has_value());
  ASSERT_TRUE(f.t95_s.has_value());  // what happened is still measured
  EXPECT_NEAR(*f.t95_s, 0.1 * std::log(20.0), kDt);
  for (const auto& name : figure_names()) {
    EXPECT_NE(unjudgeable_reason(f, name).find("too short to judge"), std::string::npos) << name;
  }
  // 1 s after the step is enough: the window is the whole post-step time, which starts outside the band.
  const Sampled one = sample(1.0, 0.0, 0.0, 1.0, [](double tau) { return first_order(0.1, tau); });
  EXPECT_EQ(figures_of(one, 0.0, 1.0).verdict, StepVerdict::kNotSettled);
  const Sampled two = sample(2.0, 0.0, 0.0, 1.0, [](double tau) { return first_order(0.1, tau); });
  EXPECT_EQ(figures_of(two, 0.0, 1.0).verdict, StepVerdict::kSettled);
}

TEST(StepVerdictTest, AZeroSizeStepHasNoFiguresAndSaysWhy) {
  const Sampled s = sample(5.0, 1.0, 2.0, 2.0, [](double tau) { return first_order(0.3, tau); });
  const StepFigures f = figures_of(s, 1.0, 2.0);
  EXPECT_EQ(f.verdict, StepVerdict::kZeroStep);
  for (const auto& name : figure_names()) {
    EXPECT_FALSE(figure(f, name).has_value()) << name;
    EXPECT_NE(unjudgeable_reason(f, name).find("zero-size step"), std::string::npos) << name;
  }
}

TEST(StepVerdictTest, AStepMidRunAndBackDownAreJudgedEachOnItsOwnSpan) {
  // Up 1 -> 3 at 2 s, back down to 1 at 9 s, end at 16 s; each step judged to the next one.
  const double T = 0.25;
  std::vector<double> t, y;
  for (int k = 0; k <= 1600; ++k) {
    const double tk = k / kRateHz;
    t.push_back(tk);
    double v = 1.0;
    if (tk >= 2.0) v = 1.0 + 2.0 * first_order(T, tk - 2.0);
    if (tk >= 9.0) v = 1.0 + (v_at(2.0, T, 7.0) - 1.0) * std::exp(-(tk - 9.0) / T);
    y.push_back(v);
  }
  const auto up_end = static_cast<std::ptrdiff_t>(900);  // samples before 9 s
  const StepFigures up = step_figures(std::span(t).first(up_end), std::span(y).first(up_end), 2.0, 3.0);
  const StepFigures down = step_figures(t, y, 9.0, 1.0);
  for (const StepFigures* f : {&up, &down}) {
    EXPECT_EQ(f->verdict, StepVerdict::kSettled);
    ASSERT_TRUE(f->settling_time_2pct_s && f->t95_s && f->rise_time_s);
    EXPECT_NEAR(*f->settling_time_2pct_s, T * std::log(50.0), kDt + 1e-9);
    EXPECT_NEAR(*f->t95_s, T * std::log(20.0), kDt + 1e-9);
    EXPECT_NEAR(*f->rise_time_s, T * std::log(9.0), kDt + 1e-9);
    EXPECT_EQ(f->overshoot_pct, 0.0);
  }
  EXPECT_NEAR(up.step, 2.0, 1e-12);
  EXPECT_NEAR(down.step, -2.0 * (1.0 - std::exp(-7.0 / T)), 1e-12);
  // Judged to the end of the run instead, the step up would see the step down in its final window.
  EXPECT_EQ(step_figures(t, y, 2.0, 3.0).verdict, StepVerdict::kNotSettled);
}

// --- Angles: the shortest-path step on the unwrapped response -----------------------------------

TEST(StepAngleTest, UnwrapRemovesTwoPiJumpsOnly) {
  const std::vector<double> y = {3.0, 3.1, -3.1, -3.0, -3.1, 3.1, 0.5};
  const std::vector<double> u = unwrap_angle(y);
  const double two_pi = 2.0 * kPi;
  const std::vector<double> expected = {3.0, 3.1, -3.1 + two_pi, -3.0 + two_pi, -3.1 + two_pi, 3.1, 0.5};
  ASSERT_EQ(u.size(), expected.size());
  for (std::size_t i = 0; i < u.size(); ++i) EXPECT_NEAR(u[i], expected[i], 1e-12) << i;
}

TEST(StepAngleTest, YawFrom3ToMinus3IsAStepOfPlus0283) {
  // The vehicle turns the short way, 3.0 -> 3.0 + (2 pi - 6) rad, and the recorded angle wraps at pi.
  const double T = 0.3, size = 2.0 * kPi - 6.0;  // 0.2832 rad
  const Sampled s = sample(8.0, 1.0, 3.0, 3.0 + size, [T](double tau) { return first_order(T, tau); });
  std::vector<double> wrapped;
  for (double v : s.y) wrapped.push_back(std::remainder(v, 2.0 * kPi));  // what the recorder writes
  ASSERT_LT(wrapped.back(), -2.9);                                       // it did wrap
  StepOptions angle;
  angle.angle = true;
  const StepFigures f = step_figures(s.t, wrapped, 1.0, -3.0, angle);
  EXPECT_NEAR(f.step, size, 1e-12);
  EXPECT_NEAR(size, 0.2832, 1e-4);
  EXPECT_EQ(f.target, -3.0);
  EXPECT_EQ(f.verdict, StepVerdict::kSettled);
  ASSERT_TRUE(f.rise_time_s && f.t95_s && f.settling_time_2pct_s && f.steady_state_error_pct);
  EXPECT_NEAR(*f.rise_time_s, T * std::log(9.0), kDt + 1e-9);
  EXPECT_NEAR(*f.t95_s, T * std::log(20.0), kDt + 1e-9);
  EXPECT_NEAR(*f.settling_time_2pct_s, T * std::log(50.0), kDt + 1e-9);
  EXPECT_NEAR(*f.steady_state_error_pct, 0.0, 1e-6);
  EXPECT_EQ(f.overshoot_pct, 0.0);

  // Judged as a plain signal, the same record is a 6 rad step that "rises" in the one sample where
  // the angle wraps (what the angle option prevents).
  const StepFigures plain = step_figures(s.t, wrapped, 1.0, -3.0);
  EXPECT_NEAR(plain.step, -6.0, 1e-12);
  ASSERT_TRUE(plain.rise_time_s.has_value());
  EXPECT_LE(*plain.rise_time_s, kDt + 1e-12);
}

TEST(StepAngleTest, AStepOfExactlyPiGoesPositive) {
  StepOptions angle;
  angle.angle = true;
  const Sampled s = sample(5.0, 0.0, 0.0, kPi, [](double tau) { return first_order(0.2, tau); });
  EXPECT_NEAR(step_figures(s.t, s.y, 0.0, -kPi, angle).step, kPi, 1e-12);  // (-pi, pi]
}

}  // namespace
}  // namespace quadcosim::analysis
