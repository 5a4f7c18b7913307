// The sensor models against independent statements of what they model: published tables (the US
// Standard Atmosphere), the hydrostatic equation, the geometry of the field's elements, the WGS-84
// ellipsoid's radii of curvature, and sample statistics of the noise.
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>
#include <numbers>
#include <vector>

#include "sensors/barometer.hpp"
#include "sensors/geodesy.hpp"
#include "sensors/gnss.hpp"
#include "sensors/magnetometer.hpp"

namespace quadcosim::sensors {
namespace {

constexpr double kDeg = std::numbers::pi / 180.0;

model::Outputs at(const Eigen::Vector3d& p_W, const Eigen::Quaterniond& q_WB = Eigen::Quaterniond::Identity(),
                  const Eigen::Vector3d& v_W = Eigen::Vector3d::Zero()) {
  model::Outputs y;
  y.p_W = p_W;
  y.q_WB = q_WB;
  y.v_W = v_W;
  y.w_B.setZero();
  y.specific_force_B.setZero();
  return y;
}

double mean(const std::vector<double>& v) {
  double s = 0.0;
  for (double x : v) s += x;
  return s / static_cast<double>(v.size());
}
double stddev(const std::vector<double>& v) {
  const double m = mean(v);
  double s = 0.0;
  for (double x : v) s += (x - m) * (x - m);
  return std::sqrt(s / static_cast<double>(v.size() - 1));
}

// --- magnetometer ---------------------------------------------------------------------------------

TEST(MagnetometerTest, TheWorldFieldHasItsIntensityDipAndDeclination) {
  const double F = 48e-6, I = 63.5 * kDeg, D = 3.2 * kDeg;
  const Eigen::Vector3d b = earth_field_W(F, I, D);
  EXPECT_NEAR(b.norm(), F, 1e-18);
  EXPECT_NEAR(std::asin(-b.z() / b.norm()), I, 1e-12);  // below the horizontal: z is up
  EXPECT_NEAR(std::atan2(b.x(), b.y()), D, 1e-12);      // east of north: x east, y north
}

TEST(MagnetometerTest, TheBodyReadingTurnsWithTheVehicle) {
  MagnetometerConfig c;
  c.field_T = 50e-6;
  c.inclination_rad = 60 * kDeg;
  c.declination_rad = 0.0;
  Magnetometer level(c, model::Rng(1));
  // Level, body x east, y north: the body reads the world field, 25 uT north, 43.3 uT down.
  const Eigen::Vector3d b0 = level.measure(at({0, 0, 0})).field_B_T;
  EXPECT_NEAR(b0.x(), 0.0, 1e-18);
  EXPECT_NEAR(b0.y(), 50e-6 * 0.5, 1e-15);
  EXPECT_NEAR(b0.z(), -50e-6 * std::sqrt(3.0) / 2.0, 1e-15);
  // Yawed 30 deg left (counter-clockwise seen from above): north now lies 30 deg to the right of the
  // body's +y axis, i.e. at body angle 90 - 30 = 60 deg from +x.
  const Eigen::Quaterniond yaw30(Eigen::AngleAxisd(30 * kDeg, Eigen::Vector3d::UnitZ()));
  const Eigen::Vector3d b1 = level.measure(at({0, 0, 0}, yaw30)).field_B_T;
  EXPECT_NEAR(std::atan2(b1.y(), b1.x()), 60 * kDeg, 1e-12);
  EXPECT_NEAR(b1.z(), b0.z(), 1e-18);
  // Rolled 90 deg about body x: body y points up, body z points south; the reading's y is the field's
  // up component (-43.3 uT) and its z the field's south component (-25 uT).
  const Eigen::Quaterniond roll90(Eigen::AngleAxisd(90 * kDeg, Eigen::Vector3d::UnitX()));
  const Eigen::Vector3d b2 = level.measure(at({0, 0, 0}, roll90)).field_B_T;
  EXPECT_NEAR(b2.y(), -50e-6 * std::sqrt(3.0) / 2.0, 1e-15);
  EXPECT_NEAR(b2.z(), -25e-6, 1e-15);
}

TEST(MagnetometerTest, HardIronAndNoise) {
  MagnetometerConfig c;
  c.hard_iron_T = {1e-6, -2e-6, 0.5e-6};
  c.noise_sigma_T = 0.3e-6;
  Magnetometer m(c, model::Rng(model::stream_seed(7, "/drone", "magnetometer")));
  const Eigen::Vector3d truth = earth_field_W(c.field_T, c.inclination_rad, c.declination_rad);
  std::vector<double> e[3];
  for (int k = 0; k < 20000; ++k) {
    const MagnetometerSample s = m.measure(at({0, 0, 0}));
    EXPECT_EQ(s.variance_T2, 0.09e-12);
    for (int i = 0; i < 3; ++i) e[i].push_back(s.field_B_T[i] - truth[i]);
  }
  for (int i = 0; i < 3; ++i) {
    // mean: the hard iron, to 4 standard errors (sigma / sqrt(20000) = 2.1 nT)
    EXPECT_NEAR(mean(e[i]), c.hard_iron_T[i], 4 * 0.3e-6 / std::sqrt(20000.0)) << i;
    EXPECT_NEAR(stddev(e[i]), 0.3e-6, 0.03 * 0.3e-6) << i;
  }
}

// --- barometer --------------------------------------------------------------------------------------

TEST(BarometerTest, TheStandardAtmosphereTable) {
  // U.S. Standard Atmosphere 1976 (= ISA below 11 km), pressure at geopotential altitude [Pa].
  const std::pair<double, double> table[] = {
      {0.0, 101325.0}, {1000.0, 89874.6}, {2000.0, 79495.2}, {5000.0, 54019.9}, {11000.0, 22632.1}};
  for (const auto& [h, p] : table) {
    EXPECT_NEAR(isa_pressure(h), p, 0.1) << h << " m";
    EXPECT_NEAR(isa_pressure_altitude(p), h, 0.02) << h << " m";
  }
  EXPECT_NEAR(isa_temperature(11000.0), 216.65, 1e-9);  // the tropopause's 216.65 K
}

TEST(BarometerTest, PressureFallsAsTheHydrostaticEquationSays) {
  // dp/dh = -rho g0 with rho = p M / (R T): the ideal gas in hydrostatic balance, checked by a central
  // difference of the closed form at several altitudes and sea-level pressures.
  for (double p0 : {101325.0, 98000.0, 103500.0}) {
    for (double h : {-200.0, 0.0, 450.0, 3000.0, 8000.0}) {
      const double dh = 0.01;
      const double slope = (isa_pressure(h + dh, p0) - isa_pressure(h - dh, p0)) / (2 * dh);
      const double p = isa_pressure(h, p0);
      const double rho = p * isa::kMolarMass_kg_mol / (isa::kGasConstant_J_mol_K * isa_temperature(h));
      EXPECT_NEAR(slope, -rho * isa::kG0_m_s2, 1e-6 * rho * isa::kG0_m_s2) << p0 << " Pa, " << h << " m";
      EXPECT_NEAR(isa_pressure_altitude(p, p0), h, 1e-8);
    }
  }
}

TEST(BarometerTest, ReadingAltitudeNoiseAndDrift) {
  BarometerConfig c;
  c.site_altitude_m = 408.0;
  Barometer ideal(c, 0.02, model::Rng(3));
  const BarometerSample s = ideal.measure(at({0, 0, 12.0}));
  EXPECT_DOUBLE_EQ(s.pressure_Pa, isa_pressure(420.0));
  EXPECT_NEAR(s.altitude_m, 420.0, 1e-9);
  EXPECT_NEAR(s.temperature_K, 288.15 - 0.0065 * 420.0, 1e-12);
  // White noise: the spread of many readings of one altitude.
  c.noise_sigma_Pa = 1.5;
  Barometer noisy(c, 0.02, model::Rng(4));
  std::vector<double> p;
  for (int k = 0; k < 20000; ++k) p.push_back(noisy.measure(at({0, 0, 0})).pressure_Pa);
  EXPECT_NEAR(stddev(p), 1.5, 0.03 * 1.5);
  EXPECT_NEAR(mean(p), isa_pressure(408.0), 4 * 1.5 / std::sqrt(20000.0));
  // Drift: after n samples of period dt the bias has variance n q^2 dt, across 2000 receivers.
  c.noise_sigma_Pa = 0.0;
  c.drift_Pa_sqrt_s = 0.5;
  std::vector<double> bias;
  for (int r = 0; r < 2000; ++r) {
    Barometer b(c, 0.02, model::Rng(model::stream_seed(static_cast<std::uint64_t>(r), "/drone", "barometer")));
    for (int k = 0; k < 100; ++k) b.measure(at({0, 0, 0}));
    bias.push_back(b.bias_Pa());
  }
  const double expected = 0.5 * std::sqrt(100 * 0.02);  // 0.707 Pa
  EXPECT_NEAR(stddev(bias), expected, 0.05 * expected);
}

// --- geodesy and GNSS -------------------------------------------------------------------------------

TEST(GeodesyTest, TheEllipsoidsAxes) {
  const Eigen::Vector3d equator = to_ecef({0.0, 0.0, 0.0});
  EXPECT_NEAR((equator - Eigen::Vector3d(6378137.0, 0, 0)).norm(), 0.0, 1e-9);
  const Eigen::Vector3d pole = to_ecef({90 * kDeg, 0.0, 0.0});
  EXPECT_NEAR(pole.z(), 6356752.314245, 1e-6);  // WGS-84's semi-minor axis b
  EXPECT_NEAR(std::hypot(pole.x(), pole.y()), 0.0, 1e-6);
  const Eigen::Vector3d east = to_ecef({0.0, 90 * kDeg, 100.0});
  EXPECT_NEAR((east - Eigen::Vector3d(0, 6378237.0, 0)).norm(), 0.0, 1e-8);
}

TEST(GeodesyTest, GeodeticToEcefAndBack) {
  for (double lat : {-89.9, -60.0, -1e-3, 0.0, 33.3, 47.3977, 89.99}) {
    for (double lon : {-179.0, 0.0, 8.5456, 120.0}) {
      for (double h : {-100.0, 0.0, 488.0, 10000.0}) {
        const Geodetic g{lat * kDeg, lon * kDeg, h};
        const Geodetic back = to_geodetic(to_ecef(g));
        EXPECT_NEAR(back.latitude_rad, g.latitude_rad, 1e-13) << lat << " " << lon << " " << h;
        EXPECT_NEAR(back.longitude_rad, g.longitude_rad, 1e-13);
        EXPECT_NEAR(back.height_m, g.height_m, 1e-6);
      }
    }
  }
}

TEST(GeodesyTest, SmallStepsFollowTheRadiiOfCurvature) {
  // On the tangent plane of a site at height h a step of d metres north changes the latitude by
  // d / (M + h) and a step east the longitude by d / ((N + h) cos lat), M and N the ellipsoid's meridian
  // and prime-vertical radii; the plane rises above the site's height surface by about d^2 / (2 (R + h))
  // (the neglected terms are ~(d/R)^2 relative).
  const Geodetic site{47.3977 * kDeg, 8.5456 * kDeg, 488.0};
  const LocalTangentPlane ltp(site);
  const double s = std::sin(site.latitude_rad);
  const double w = 1.0 - wgs84::kE2 * s * s;
  const double M = wgs84::kA_m * (1.0 - wgs84::kE2) / std::pow(w, 1.5);
  const double N = wgs84::kA_m / std::sqrt(w);
  const double d = 100.0;
  const Geodetic north = ltp.to_geodetic({0, d, 0});
  const double h = site.height_m;
  EXPECT_NEAR((north.latitude_rad - site.latitude_rad) * (M + h), d, 1e-5);
  EXPECT_NEAR(north.longitude_rad, site.longitude_rad, 1e-15);
  EXPECT_NEAR(north.height_m - h, d * d / (2 * (M + h)), 1e-5);
  const Geodetic east = ltp.to_geodetic({d, 0, 0});
  EXPECT_NEAR((east.longitude_rad - site.longitude_rad) * (N + h) * std::cos(site.latitude_rad), d, 1e-5);
  EXPECT_NEAR(east.height_m - h, d * d / (2 * (N + h)), 1e-5);
  const Geodetic up = ltp.to_geodetic({0, 0, 35.0});
  EXPECT_NEAR(up.latitude_rad, site.latitude_rad, 1e-15);
  EXPECT_NEAR(up.longitude_rad, site.longitude_rad, 1e-15);
  EXPECT_NEAR(up.height_m, site.height_m + 35.0, 1e-8);
  EXPECT_NEAR((ltp.to_enu(ltp.to_geodetic({12.5, -40.0, 7.0})) - Eigen::Vector3d(12.5, -40.0, 7.0)).norm(), 0.0, 1e-8);
}

// An outage loses the fix over [outage_from_s, outage_to_s) of measured time and nowhere else; the
// noise after it is drawn as if there had been none (the stream is not advanced without a fix).
TEST(GnssTest, AnOutageLosesTheFixOverItsWindow) {
  GnssConfig c;
  c.site = {47.3977 * kDeg, 8.5456 * kDeg, 488.0};
  c.horizontal_sigma_m = 0.5;
  GnssConfig with = c;
  with.outage_from_s = 3.0;
  with.outage_to_s = 4.5;
  EXPECT_EQ(check(with), "");
  Gnss plain(c, model::Rng(7)), lossy(with, model::Rng(7));
  const Eigen::Vector3d p(5.0, -3.0, 12.0);
  for (int k = 0; k <= 60; ++k) {
    const double t = 0.1 * k;
    const bool lost = k >= 30 && k < 45;  // 3.0 <= t < 4.5, by tenths
    const GnssSample a = lossy.measure(at(p), t);
    EXPECT_EQ(a.fix, !lost) << t;
    if (lost) {
      EXPECT_TRUE(std::isnan(a.position.latitude_rad) && std::isnan(a.velocity_W.z())) << t;
      continue;
    }
    const GnssSample b = plain.measure(at(p), t);
    EXPECT_EQ(a.position.latitude_rad, b.position.latitude_rad) << t;
  }
  GnssConfig backwards = c;
  backwards.outage_from_s = 4.0;
  backwards.outage_to_s = 3.0;
  EXPECT_NE(check(backwards).find("is not after outage_from_s"), std::string::npos);
}

TEST(GnssTest, NoFixThenAFixWithItsSpread) {
  GnssConfig c;
  c.site = {47.3977 * kDeg, 8.5456 * kDeg, 488.0};
  c.fix_after_s = 2.0;
  c.horizontal_sigma_m = 0.8;
  c.vertical_sigma_m = 1.5;
  c.velocity_sigma_m_s = 0.1;
  Gnss g(c, model::Rng(model::stream_seed(1, "/drone", "gnss")));
  const GnssSample none = g.measure(at({3, 4, 5}), 1.9);
  EXPECT_FALSE(none.fix);
  EXPECT_TRUE(std::isnan(none.position.latitude_rad) && std::isnan(none.velocity_W.x()));
  std::vector<double> e[3], v[3];
  const Eigen::Vector3d p(30.0, -20.0, 10.0), vel(1.0, 2.0, -0.5);
  for (int k = 0; k < 20000; ++k) {
    const GnssSample s = g.measure(at(p, Eigen::Quaterniond::Identity(), vel), 2.0 + 0.1 * k);
    ASSERT_TRUE(s.fix);
    EXPECT_NEAR((s.position_variance_enu - Eigen::Vector3d(0.64, 0.64, 2.25)).norm(), 0.0, 1e-15);
    const Eigen::Vector3d enu = g.plane().to_enu(s.position);
    for (int i = 0; i < 3; ++i) {
      e[i].push_back(enu[i] - p[i]);
      v[i].push_back(s.velocity_W[i] - vel[i]);
    }
  }
  const double sigma[3] = {0.8, 0.8, 1.5};
  for (int i = 0; i < 3; ++i) {
    EXPECT_NEAR(mean(e[i]), 0.0, 4 * sigma[i] / std::sqrt(20000.0)) << i;
    EXPECT_NEAR(stddev(e[i]), sigma[i], 0.03 * sigma[i]) << i;
    EXPECT_NEAR(stddev(v[i]), 0.1, 0.003) << i;
  }
  // Without noise the fix is the truth, to the conversion's precision.
  GnssConfig ideal;
  ideal.site = c.site;
  Gnss exact(ideal, model::Rng(0));
  const GnssSample s = exact.measure(at(p, Eigen::Quaterniond::Identity(), vel), 0.0);
  EXPECT_TRUE(s.fix);
  EXPECT_NEAR((exact.plane().to_enu(s.position) - p).norm(), 0.0, 1e-8);
  EXPECT_EQ(s.velocity_W, vel);
}

}  // namespace
}  // namespace quadcosim::sensors
