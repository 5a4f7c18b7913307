// The scenario key `trajectory:`: each kind read into the trajectory it names, and bad sections
// refused with the file, key path and value.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <numbers>
#include <string>

#include "hosts/scenario_resolvers_test_support.hpp"
#include "io/scenario.hpp"
#include "trajectory/piecewise_polynomial.hpp"

namespace quadcosim::io {
namespace {

namespace fs = std::filesystem;

/// A directory of its own per test (the file kind reads beside the scenario).
fs::path test_dir() {
  const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
  const fs::path d = fs::path(::testing::TempDir()) / (std::string("trajectory_yaml_") + info->name());
  fs::create_directories(d);
  return d;
}

std::string write(const fs::path& path, const std::string& text) {
  std::ofstream(path, std::ios::binary) << text;
  return path.string();
}

Scenario load(const std::string& trajectory_yaml) {
  return load_scenario(write(test_dir() / "scenario.yaml", "simulation: {duration_s: 1}\n" + trajectory_yaml),
                       hosts::test_resolvers());
}

std::string error_of(const std::string& trajectory_yaml) {
  const std::string path = (test_dir() / "scenario.yaml").string();
  try {
    load(trajectory_yaml);
  } catch (const ConfigError& e) {
    const std::string msg = e.what();
    EXPECT_EQ(msg.rfind(path + ": ", 0), 0u) << msg;
    return msg;
  }
  ADD_FAILURE() << "no error for " << trajectory_yaml;
  return "";
}

TEST(TrajectoryYamlTest, AbsentOrStepsIsNoTrajectory) {
  EXPECT_EQ(load("").controller.trajectory, nullptr);
  EXPECT_EQ(load("trajectory: {kind: steps}\n").controller.trajectory, nullptr);
}

TEST(TrajectoryYamlTest, CircleKeysAreRead) {
  const Scenario sc = load(R"(trajectory:
  kind: circle
  centre_m: [1, 2]
  altitude_m: 5
  radius_m: 2
  period_s: 10
  direction: cw
  phase_rad: 0
  start_s: 1
  ramp_s: 0
  yaw_mode: centre
)");
  ASSERT_NE(sc.controller.trajectory, nullptr);
  EXPECT_EQ(sc.controller.trajectory->describe().rfind("circle r=2 m, period 10 s cw about (1, 2) at 5 m", 0), 0u)
      << sc.controller.trajectory->describe();
  // A quarter period after the abrupt start at (3, 2), clockwise: (1, 0), facing the centre (+y).
  const auto o = sc.controller.trajectory->at(1.0 + 2.5);
  EXPECT_NEAR(o.p_W.x(), 1.0, 1e-12);
  EXPECT_NEAR(o.p_W.y(), 0.0, 1e-12);
  EXPECT_EQ(o.p_W.z(), 5.0);
  EXPECT_NEAR(o.yaw_rad, std::numbers::pi / 2, 1e-12);
}

TEST(TrajectoryYamlTest, LissajousAndFigure8AreRead) {
  const Scenario l = load(
      "trajectory: {kind: lissajous, amplitude_m: [2, 1], period_s: [8, 4], phase_rad: [0, 1], altitude_m: 2, "
      "ramp_s: 0, yaw_mode: tangent}\n");
  ASSERT_NE(l.controller.trajectory, nullptr);
  EXPECT_NEAR(l.controller.trajectory->at(2.0).p_W.x(), 2.0, 1e-12);  // sin(2 pi / 8 * 2)
  EXPECT_NEAR(l.controller.trajectory->at(2.0).p_W.y(), std::sin(std::numbers::pi + 1.0), 1e-12);
  const Scenario f = load("trajectory: {kind: figure8, amplitude_m: [3, 1], period_s: 12, ramp_s: 0}\n");
  ASSERT_NE(f.controller.trajectory, nullptr);
  EXPECT_NEAR(f.controller.trajectory->at(3.0).p_W.x(), 3.0, 1e-12);
  EXPECT_NEAR(f.controller.trajectory->at(3.0).p_W.y(), 0.0, 1e-12);
  EXPECT_EQ(f.controller.trajectory->at(3.0).p_W.z(), 1.0);  // default altitude
}

TEST(TrajectoryYamlTest, WaypointsAreRead) {
  const Scenario sc = load(R"(trajectory:
  kind: waypoints
  method: min_jerk
  points:
    - {t_s: 1, position_m: [0, 0, 1]}
    - {t_s: 3, position_m: [2, 0, 1], yaw_rad: 1.5}
)");
  ASSERT_NE(sc.controller.trajectory, nullptr);
  EXPECT_EQ(sc.controller.trajectory->end_s(), 3.0);
  EXPECT_NEAR(sc.controller.trajectory->at(2.0).p_W.x(), 1.0, 1e-12);
  EXPECT_NEAR(sc.controller.trajectory->at(1.5).p_W.x(), 2.0 * (10.0 / 64 - 15.0 / 256 + 6.0 / 1024), 1e-12);
  EXPECT_NEAR(sc.controller.trajectory->at(3.0).yaw_rad, 1.5, 1e-12);
  EXPECT_EQ(sc.controller.trajectory->describe().rfind("min_jerk through 2 waypoints", 0), 0u);
}

TEST(TrajectoryYamlTest, FilePathIsRelativeToTheScenario) {
  const fs::path dir = test_dir();
  fs::create_directories(dir / "paths");
  std::string csv = "Duration";
  for (const char* a : {"x", "y", "z", "yaw"}) {
    for (int i = 0; i < 8; ++i) csv += std::string(",") + a + "^" + std::to_string(i);
  }
  csv += "\n2";
  for (int c = 0; c < 32; ++c) csv += c == 0 ? ",1" : (c == 1 ? ",0.5" : (c == 16 ? ",2" : ",0"));
  write(dir / "paths" / "line.csv", csv + "\n");
  const Scenario sc = load("trajectory: {kind: file, path: paths/line.csv, start_s: 1}\n");
  ASSERT_NE(sc.controller.trajectory, nullptr);
  EXPECT_EQ(sc.controller.trajectory->end_s(), 3.0);
  EXPECT_DOUBLE_EQ(sc.controller.trajectory->at(2.0).p_W.x(), 1.5);  // 1 + 0.5 tau at tau = 1
  EXPECT_DOUBLE_EQ(sc.controller.trajectory->at(2.0).v_W.x(), 0.5);
  EXPECT_DOUBLE_EQ(sc.controller.trajectory->at(2.0).p_W.z(), 2.0);
}

struct BadTrajectory {
  std::string label, yaml;
  std::vector<std::string> must_mention;
};

class BadTrajectoryTest : public ::testing::TestWithParam<BadTrajectory> {};

TEST_P(BadTrajectoryTest, ErrorNamesKeyAndValue) {
  const std::string msg = error_of(GetParam().yaml);
  for (const std::string& s : GetParam().must_mention) {
    EXPECT_NE(msg.find(s), std::string::npos) << "'" << s << "' missing from: " << msg;
  }
}

INSTANTIATE_TEST_SUITE_P(
    Scenario, BadTrajectoryTest,
    ::testing::Values(
        BadTrajectory{"kind", "trajectory: {kind: spiral}\n", {"trajectory.kind: got 'spiral'", "'figure8'"}},
        BadTrajectory{"unknown_key", "trajectory: {kind: circle, radius: 2}\n", {"trajectory.radius: unknown key"}},
        BadTrajectory{"steps_with_keys", "trajectory: {radius_m: 2}\n", {"trajectory.radius_m: unknown key"}},
        BadTrajectory{"radius", "trajectory: {kind: circle, radius_m: 0}\n", {"trajectory.radius_m: got '0'"}},
        BadTrajectory{"period", "trajectory: {kind: circle, period_s: fast}\n", {"trajectory.period_s: got 'fast'"}},
        BadTrajectory{
            "direction", "trajectory: {kind: circle, direction: left}\n", {"trajectory.direction: got 'left'", "'cw'"}},
        BadTrajectory{"yaw_mode",
                      "trajectory: {kind: figure8, yaw_mode: centre}\n",
                      {"trajectory.yaw_mode: got 'centre'", "'tangent'"}},
        BadTrajectory{"yaw_with_tangent",
                      "trajectory: {kind: circle, yaw_mode: tangent, yaw_rad: 1}\n",
                      {"trajectory.yaw_rad: given with yaw_mode 'tangent'"}},
        BadTrajectory{"amplitude",
                      "trajectory: {kind: lissajous, amplitude_m: [1, -2]}\n",
                      {"trajectory.amplitude_m: got an entry -2"}},
        BadTrajectory{"ramp", "trajectory: {kind: figure8, ramp_s: -1}\n", {"trajectory.ramp_s: got '-1'"}},
        BadTrajectory{"one_waypoint",
                      "trajectory: {kind: waypoints, points: [{t_s: 0, position_m: [0, 0, 1]}]}\n",
                      {"trajectory.points: got 1 waypoints, expected at least two"}},
        BadTrajectory{"waypoint_order",
                      "trajectory: {kind: waypoints, points: [{t_s: 2, position_m: [0, 0, 1]}, "
                      "{t_s: 2, position_m: [1, 0, 1]}]}\n",
                      {"trajectory.points[1].t_s: got 2, expected a time after the previous waypoint's (2 s)"}},
        BadTrajectory{"waypoint_underground",
                      "trajectory: {kind: waypoints, points: [{t_s: 0, position_m: [0, 0, -1]}, "
                      "{t_s: 2, position_m: [1, 0, 1]}]}\n",
                      {"trajectory.points[0].position_m: got z = -1"}},
        BadTrajectory{"waypoint_key",
                      "trajectory: {kind: waypoints, points: [{t_s: 0, position_m: [0, 0, 1], yaw: 1}, "
                      "{t_s: 2, position_m: [1, 0, 1]}]}\n",
                      {"trajectory.points[0].yaw: unknown key"}},
        BadTrajectory{"waypoint_missing",
                      "trajectory: {kind: waypoints, points: [{t_s: 0}, {t_s: 1}]}\n",
                      {"trajectory.points[0].position_m: missing"}},
        BadTrajectory{
            "method", "trajectory: {kind: waypoints, method: min_crackle}\n", {"trajectory.method: got 'min_crackle'"}},
        BadTrajectory{"file_missing_path", "trajectory: {kind: file}\n", {"trajectory.path: missing"}},
        BadTrajectory{"file_not_there",
                      "trajectory: {kind: file, path: nowhere.csv}\n",
                      {"trajectory.path: got 'nowhere.csv':", "nowhere.csv: cannot open the file"}}));

}  // namespace
}  // namespace quadcosim::io
