#include "analysis/tracking.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <numbers>
#include <vector>

namespace quadcosim::analysis {
namespace {

constexpr double kNan = std::numeric_limits<double>::quiet_NaN();

// A synthetic record at 100 Hz over [0, duration_s]: reference and measured columns set by the test.
struct Record {
  std::vector<double> t, x_des, y_des, z_des, yaw_des, x, y, z, yaw, psi;
  explicit Record(double duration_s) {
    const int n = static_cast<int>(std::lround(duration_s * 100.0)) + 1;
    for (int i = 0; i < n; ++i) t.push_back(i * 0.01);
    for (auto* c : {&x_des, &y_des, &z_des, &yaw_des, &x, &y, &z, &yaw}) c->assign(t.size(), 0.0);
  }
  TrackingSeries series() const { return {t, x_des, y_des, z_des, yaw_des, x, y, z, yaw, psi}; }
};

TEST(Tracking, ConstantOffsetInXIsItsOwnRmseAndMax) {
  Record r(10.0);
  for (std::size_t i = 0; i < r.t.size(); ++i) {
    r.x_des[i] = 2.0 * std::cos(r.t[i]);
    r.y_des[i] = 2.0 * std::sin(r.t[i]);
    r.z_des[i] = 5.0;
    r.x[i] = r.x_des[i] - 0.03;  // 3 cm behind in x, exact elsewhere
    r.y[i] = r.y_des[i];
    r.z[i] = 5.0;
  }
  const TrackingFigures f = tracking_figures(r.series(), 0.0);
  EXPECT_EQ(f.samples, 1001u);
  EXPECT_NEAR(f.values.at("x_rmse_m"), 0.03, 1e-12);
  EXPECT_NEAR(f.values.at("x_max_m"), 0.03, 1e-12);
  EXPECT_NEAR(f.values.at("position_rmse_m"), 0.03, 1e-12);
  EXPECT_NEAR(f.values.at("position_max_m"), 0.03, 1e-12);
  EXPECT_DOUBLE_EQ(f.values.at("y_rmse_m"), 0.0);
  EXPECT_DOUBLE_EQ(f.values.at("z_max_m"), 0.0);
  EXPECT_DOUBLE_EQ(f.values.at("yaw_rmse_rad"), 0.0);
  // No Psi column: its figures are absent, not zero.
  EXPECT_EQ(f.values.count("attitude_error_rmse"), 0u);
  EXPECT_EQ(f.values.count("attitude_error_max"), 0u);
}

TEST(Tracking, SinusoidalErrorHasRmsAmplitudeOverRootTwo) {
  Record r(10.0);  // whole periods of 1 s: the RMS of a sine is exactly A / sqrt(2) over them
  const double a = 0.1;
  for (std::size_t i = 0; i < r.t.size(); ++i) r.z[i] = a * std::sin(2.0 * std::numbers::pi * r.t[i]);
  // One period's samples at 100 Hz: RMS over the 1001 samples (the last repeats the first, 0) is
  // A sqrt(500 / 1001), within 0.05 % of A / sqrt(2).
  const TrackingFigures f = tracking_figures(r.series(), 0.0);
  EXPECT_NEAR(f.values.at("z_rmse_m"), a * std::sqrt(500.0 / 1001.0), 1e-12);
  EXPECT_NEAR(f.values.at("z_rmse_m"), a / std::sqrt(2.0), 1e-4);
  EXPECT_NEAR(f.values.at("position_rmse_m"), f.values.at("z_rmse_m"), 1e-15);
  EXPECT_NEAR(f.values.at("z_max_m"), a, 1e-12);  // the sample at t = 0.25 s
}

TEST(Tracking, ThreeAxisErrorIsEuclidean) {
  Record r(1.0);
  for (std::size_t i = 0; i < r.t.size(); ++i) {
    r.x[i] = 0.03;
    r.y[i] = -0.04;  // |(0.03, -0.04, 0.12)| = 0.13
    r.z[i] = 0.12;
  }
  const TrackingFigures f = tracking_figures(r.series(), 0.0);
  EXPECT_NEAR(f.values.at("position_rmse_m"), 0.13, 1e-12);
  EXPECT_NEAR(f.values.at("position_max_m"), 0.13, 1e-12);
  EXPECT_NEAR(f.values.at("y_max_m"), 0.04, 1e-12);
}

TEST(Tracking, YawErrorIsWrapped) {
  Record r(1.0);
  const double deg = std::numbers::pi / 180.0;
  for (std::size_t i = 0; i < r.t.size(); ++i) {
    r.yaw_des[i] = 179.0 * deg;
    r.yaw[i] = -179.0 * deg;  // 2 degrees apart across +-pi, not 358
  }
  const TrackingFigures f = tracking_figures(r.series(), 0.0);
  EXPECT_NEAR(f.values.at("yaw_rmse_rad"), 2.0 * deg, 1e-12);
}

TEST(Tracking, NanPsiSamplesAreSkippedAndAllNanMeansAbsent) {
  Record r(1.0);
  r.psi.assign(r.t.size(), kNan);
  EXPECT_EQ(tracking_figures(r.series(), 0.0).values.count("attitude_error_rmse"), 0u);
  // Psi 0.02 on the first half, NaN on the rest (a controller that stopped reporting one).
  for (std::size_t i = 0; i < r.t.size() / 2; ++i) r.psi[i] = 0.02;
  r.psi[3] = 0.05;
  const TrackingFigures f = tracking_figures(r.series(), 0.0);
  const double n = static_cast<double>(r.t.size() / 2);
  EXPECT_NEAR(f.values.at("attitude_error_rmse"), std::sqrt(((n - 1) * 0.02 * 0.02 + 0.05 * 0.05) / n), 1e-15);
  EXPECT_DOUBLE_EQ(f.values.at("attitude_error_max"), 0.05);
  EXPECT_EQ(f.samples, r.t.size());  // position figures still count every sample
}

TEST(Tracking, OnlySamplesFromAfterSCount) {
  Record r(20.0);
  for (std::size_t i = 0; i < r.t.size(); ++i) r.x[i] = r.t[i] < 10.0 ? 1.0 : 0.01;  // a large start-up error
  const TrackingFigures f = tracking_figures(r.series(), 10.0);
  EXPECT_EQ(f.samples, 1001u);  // t = 10.00 .. 20.00
  EXPECT_NEAR(f.values.at("x_rmse_m"), 0.01, 1e-12);
  EXPECT_NEAR(f.values.at("x_max_m"), 0.01, 1e-12);
  // From 0 the start-up error dominates: sqrt((1000 * 1 + 1001 * 1e-4) / 2001).
  EXPECT_NEAR(tracking_figures(r.series(), 0.0).values.at("x_rmse_m"), std::sqrt((1000.0 + 0.1001) / 2001.0), 1e-12);
}

TEST(Tracking, SamplesWithoutAReferenceAreSkipped) {
  Record r(1.0);
  for (std::size_t i = 0; i < 10; ++i) r.x_des[i] = kNan;  // before the controller's first status
  r.x.assign(r.t.size(), 0.02);
  const TrackingFigures f = tracking_figures(r.series(), 0.0);
  EXPECT_EQ(f.samples, r.t.size() - 10);
  EXPECT_NEAR(f.values.at("x_rmse_m"), 0.02, 1e-12);
  // No sample after after_s: no figures at all.
  const TrackingFigures none = tracking_figures(r.series(), 5.0);
  EXPECT_EQ(none.samples, 0u);
  EXPECT_TRUE(none.values.empty());
}

TEST(Tracking, OnlyControllerStepsCountWithAReferencePeriod) {
  // A reference held between 50 Hz controller steps against a position moving at 1 m/s, sampled at
  // 100 Hz: the samples between steps see the reference 10 ms old (1 cm behind); at the steps the
  // vehicle is exactly on it.
  Record r(2.0);
  for (std::size_t i = 0; i < r.t.size(); ++i) {
    r.x[i] = r.t[i];
    r.x_des[i] = r.t[i - i % 2];
  }
  const TrackingFigures every = tracking_figures(r.series(), 0.0);
  EXPECT_NEAR(every.values.at("x_max_m"), 0.01, 1e-12);
  EXPECT_EQ(every.samples, 201u);
  const TrackingFigures steps = tracking_figures(r.series(), 0.0, 0.02);
  EXPECT_EQ(steps.samples, 101u);  // t = 0, 0.02, ..., 2.00
  EXPECT_DOUBLE_EQ(steps.values.at("x_max_m"), 0.0);
  EXPECT_THROW(tracking_figures(r.series(), 0.0, -0.02), std::invalid_argument);
}

TEST(Tracking, ColumnsOfDifferentLengthsAreRefused) {
  Record r(1.0);
  r.yaw.pop_back();
  EXPECT_THROW(tracking_figures(r.series(), 0.0), std::invalid_argument);
  Record q(1.0);
  q.psi = {0.1};
  EXPECT_THROW(tracking_figures(q.series(), 0.0), std::invalid_argument);
}

TEST(Tracking, FigureNamesAreTheFiguresComputed) {
  Record r(1.0);
  r.psi.assign(r.t.size(), 0.0);
  const TrackingFigures f = tracking_figures(r.series(), 0.0);
  ASSERT_EQ(f.values.size(), tracking_figure_names().size());
  for (const auto& name : tracking_figure_names()) EXPECT_EQ(f.values.count(name), 1u) << name;
}

}  // namespace
}  // namespace quadcosim::analysis
