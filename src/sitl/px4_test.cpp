// PX4's side of the bridge (px4.hpp) against numbers written out here: airframe 10016's motor table,
// the unit changes of HIL_SENSOR and HIL_GPS worked by hand, the mode numbers of PX4's custom modes.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>
#include <numbers>

#include "model/mixer.hpp"
#include "sitl/motor_map.hpp"
#include "sitl/px4.hpp"

namespace quadcosim::sitl::px4 {
namespace {

constexpr double kDeg = std::numbers::pi / 180.0;

std::map<std::string, std::string> as_map(const std::vector<std::pair<std::string, std::string>>& v) {
  return {v.begin(), v.end()};
}

// Airframe 10016 (none_iris): outputs 1..4 at (x, y) FRD signs and turning (KM > 0: counter-clockwise).
struct TableRow {
  int px, py, km;
};
constexpr TableRow kIris[4] = {{+1, +1, +1}, {-1, -1, +1}, {+1, -1, -1}, {-1, +1, -1}};

TEST(Px4Motors, XLayoutTakesAirframe10016sOutputs) {
  model::VehicleParams v;
  v.layout = model::RotorLayout::kX;
  const MotorMap map = motor_map_for(v);
  const auto p = as_map(vehicle_params(v, map));
  for (int out = 0; out < 4; ++out) {
    int rotor = 0;
    while (map.channel_of_rotor[rotor] != out) ++rotor;
    // quadcosim's rotor position (body FLU) and turn, against the table's quadrant and direction.
    const Eigen::Vector3d r = model::rotor_position_B(v, rotor);
    EXPECT_EQ(r.x() > 0 ? 1 : -1, kIris[out].px) << "output " << out + 1;
    EXPECT_EQ(-r.y() > 0 ? 1 : -1, kIris[out].py) << "output " << out + 1;  // FLU y left, FRD y right
    EXPECT_EQ(v.spin[static_cast<std::size_t>(rotor)] == -1 ? 1 : -1, kIris[out].km) << "output " << out + 1;
    // What PX4 is told: the same quadrant, 0.59 m / sqrt(2) = 0.417193 m out, KM = k_m / k_t with the turn's sign.
    const std::string n = "CA_ROTOR" + std::to_string(out) + "_";
    EXPECT_NEAR(std::stod(p.at(n + "PX")), kIris[out].px * 0.417193, 1e-6);
    EXPECT_NEAR(std::stod(p.at(n + "PY")), kIris[out].py * 0.417193, 1e-6);
    EXPECT_NEAR(std::stod(p.at(n + "KM")), kIris[out].km * 1.01e-10 / 2.06e-7, 1e-9);
  }
  // Rotor 1 (front-left) is output 3, 2 (front-right) output 1, 3 (back-right) output 4, 4 output 2.
  EXPECT_EQ(map.channel_of_rotor, (std::array<int, 4>{2, 0, 3, 1}));
}

TEST(Px4Motors, PlusLayoutPositionsAndTheHoverThrust) {
  model::VehicleParams v;  // '+', arm 0.59 m
  v.motor.omega_max_rad_s = 7000.0;
  const auto p = as_map(vehicle_params(v, motor_map_for(v)));
  // Output 1 drives rotor 2 (right): FRD (0, +0.59); output 3 rotor 1 (front): (0.59, 0). An exact 0
  // goes as 1 um (PX4 would drop a value equal to its default of the moment).
  EXPECT_EQ(p.at("CA_ROTOR0_PX"), "0.000001");
  EXPECT_EQ(p.at("CA_ROTOR0_PY"), "0.59");
  EXPECT_EQ(p.at("CA_ROTOR1_PY"), "-0.59");
  EXPECT_EQ(p.at("CA_ROTOR2_PX"), "0.59");
  EXPECT_EQ(p.at("CA_ROTOR3_PX"), "-0.59");
  EXPECT_EQ(p.at("CA_ROTOR_COUNT"), "4");
  EXPECT_EQ(p.at("THR_MDL_FAC"), "1");
  // m g / (4 k_t w_max^2) = 1.96 * 9.81 / (4 * 2.06e-7 * 7000^2) = 0.476181
  EXPECT_EQ(p.at("MPC_THR_HOVER"), "0.4762");
}

TEST(Px4Motors, ControlsToRotorSpeeds) {
  model::VehicleParams v;
  const MotorMap map = motor_map_for(v);  // omega_max 12000
  std::array<float, 16> c{};
  c[0] = 0.25f;
  c[1] = 0.5f;
  c[2] = 0.75f;
  c[3] = 1.0f;
  const Eigen::Vector4d w = omega_from_controls(map, c);
  EXPECT_EQ(w, Eigen::Vector4d(9000.0, 3000.0, 12000.0, 6000.0));
  c[0] = 1.5f;
  c[1] = -0.5f;
  c[2] = NAN;
  const Eigen::Vector4d clipped = omega_from_controls(map, c);
  EXPECT_EQ(clipped, Eigen::Vector4d(0.0, 12000.0, 12000.0, 0.0));
}

TEST(Px4Messages, HilSensorInPx4sFramesAndUnits) {
  control::Observation obs;
  obs.specific_force_B = {0.5, 0.25, 9.75};  // FLU
  obs.w_B = {0.1, 0.2, -0.3};
  obs.sensors.carry<sensors::MagnetometerKind>();
  obs.sensors.carry<sensors::BarometerKind>();
  sensors::MagnetometerSample mag;
  mag.field_B_T = {2e-5, -1e-5, -4e-5};  // 0.2, -0.1, -0.4 gauss FLU
  obs.sensors.set<sensors::MagnetometerKind>(mag, 20'000'000);
  sensors::BarometerSample baro;
  baro.pressure_Pa = 95000.0;
  baro.altitude_m = 540.0;
  obs.sensors.set<sensors::BarometerKind>(baro, 20'000'000);

  const mavlink::HilSensor imu_only = hil_sensor(obs, 4000, false, false);
  EXPECT_EQ(imu_only.time_usec, 4000u);
  EXPECT_EQ(imu_only.fields_updated, 0x3Fu);
  EXPECT_EQ(imu_only.acc_m_s2, (std::array<float, 3>{0.5f, -0.25f, -9.75f}));
  EXPECT_EQ(imu_only.gyro_rad_s, (std::array<float, 3>{0.1f, -0.2f, 0.3f}));
  EXPECT_EQ(imu_only.mag_gauss, (std::array<float, 3>{0, 0, 0}));

  const mavlink::HilSensor all = hil_sensor(obs, 8000, true, true);
  EXPECT_EQ(all.fields_updated, 0x3Fu | 0x1C0u | 0x200u | 0x800u | 0x1000u);
  EXPECT_FLOAT_EQ(all.mag_gauss[0], 0.2f);
  EXPECT_FLOAT_EQ(all.mag_gauss[1], 0.1f);
  EXPECT_FLOAT_EQ(all.mag_gauss[2], 0.4f);
  EXPECT_FLOAT_EQ(all.abs_pressure_hpa, 950.0f);
  EXPECT_FLOAT_EQ(all.pressure_alt_m, 540.0f);
  EXPECT_FLOAT_EQ(all.temperature_c, 15.0f - 3.51f);  // 15 degC - 6.5 K/km * 0.54 km
}

TEST(Px4Messages, HilGpsInPx4sUnits) {
  sensors::GnssSample s;
  s.fix = true;
  s.position = {47.397742 * kDeg, 8.545594 * kDeg, 498.25};
  s.position_variance_enu = {0.09, 0.09, 0.25};
  s.velocity_W = {3.0, 4.0, -1.0};  // east, north, up
  const mavlink::HilGps g = hil_gps(s, 1234);
  EXPECT_EQ(g.time_usec, 1234u);
  EXPECT_EQ(g.lat, 473977420);
  EXPECT_EQ(g.lon, 85455940);
  EXPECT_EQ(g.alt, 498250);
  EXPECT_EQ(g.eph, 30);
  EXPECT_EQ(g.epv, 50);
  EXPECT_EQ(g.vn, 400);
  EXPECT_EQ(g.ve, 300);
  EXPECT_EQ(g.vd, 100);
  EXPECT_EQ(g.vel, 500);
  EXPECT_EQ(g.cog, 3687);  // atan2(3, 4) = 36.87 deg east of north
  EXPECT_EQ(g.fix_type, 3);
  EXPECT_EQ(g.satellites_visible, 10);
  sensors::GnssSample none;
  none.position = {NAN, NAN, NAN};
  const mavlink::HilGps n = hil_gps(none, 1);
  EXPECT_EQ(n.fix_type, 1);
  EXPECT_EQ(n.satellites_visible, 0);
  EXPECT_EQ(n.lat, 0);
  EXPECT_EQ(utc_usec(2.5), 1767225600ULL * 1000000ULL + 2500000ULL);
}

TEST(Px4Modes, CustomModeNumbers) {
  EXPECT_EQ(mode_numbers("land")->main, 4);
  EXPECT_EQ(mode_numbers("land")->sub, 6);
  EXPECT_EQ(mode_numbers("takeoff")->sub, 2);
  EXPECT_EQ(mode_numbers("loiter")->sub, 3);
  EXPECT_EQ(mode_numbers("posctl")->main, 3);
  EXPECT_EQ(mode_numbers("offboard")->main, 6);
  EXPECT_FALSE(mode_numbers("guided").has_value());
}

TEST(Px4Params, FileLinesAndTheirErrors) {
  const auto dir = std::filesystem::temp_directory_path();
  const auto good = (dir / "px4_test_good.parm").string();
  std::ofstream(good) << "# a comment\n\nMC_ROLLRATE_P 0.05\nCOM_RC_IN_MODE,4  # trailing\n";
  const auto p = read_param_file(good);
  ASSERT_EQ(p.size(), 2u);
  EXPECT_EQ(p[0], (std::pair<std::string, std::string>{"MC_ROLLRATE_P", "0.05"}));
  EXPECT_EQ(p[1], (std::pair<std::string, std::string>{"COM_RC_IN_MODE", "4"}));
  const auto bad = (dir / "px4_test_bad.parm").string();
  std::ofstream(bad) << "MC_ROLLRATE_P 0.05\nmc_rollrate_p fast\n";
  try {
    read_param_file(bad);
    FAIL() << "no error";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("px4_test_bad.parm:2: expected NAME VALUE"), std::string::npos) << e.what();
  }
  std::remove(good.c_str());
  std::remove(bad.c_str());
}

}  // namespace
}  // namespace quadcosim::sitl::px4
