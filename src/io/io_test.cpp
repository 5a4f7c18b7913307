// Tests of the file layer: scenario loading and its error messages, the trajectory CSV, command
// schedules, and the step report (criteria and metrics.json).
#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <stdlib.h>
#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>
#include <map>
#include <nlohmann/json.hpp>
#include <numbers>
#include <sstream>
#include <stdexcept>
#include <string>
#include <variant>
#include <vector>

#include "controllers/paper/paper_controller.hpp"
#include "hosts/scenario_resolvers_test_support.hpp"
#include "io/scenario.hpp"
#include "io/step_report.hpp"
#include "io/trajectory_csv.hpp"
#include "model/attitude.hpp"

namespace quadcosim::io {
namespace {

namespace fs = std::filesystem;
using ::testing::HasSubstr;
using ::testing::StartsWith;
using ::testing::ThrowsMessage;

const fs::path kSourceDir = QUADCOSIM_SOURCE_DIR;

// The parameters of the paper controller a configuration flies (it must fly one).
const controllers::PaperParams& paper_params(const control::ControllerConfig& c) {
  const controllers::PaperController* pc = controllers::paper_controller(c);
  if (pc == nullptr) throw std::logic_error("not a paper controller");
  return pc->params();
}

// The defaults of the paper controller.
const controllers::PaperParams kPaperDefaults{};

/// A fresh directory under the system temp dir, removed with everything in it at the end of the test.
class TempDir {
 public:
  TempDir() {
    std::string pattern = (fs::temp_directory_path() / "quadcosim_io_test_XXXXXX").string();
    if (!mkdtemp(pattern.data())) throw std::runtime_error("mkdtemp failed");
    path_ = pattern;
  }
  ~TempDir() {
    std::error_code ec;
    fs::remove_all(path_, ec);
  }
  TempDir(const TempDir&) = delete;
  TempDir& operator=(const TempDir&) = delete;

  /// Writes `text` to `name` inside the directory; returns the full path.
  std::string write(const std::string& name, const std::string& text) const {
    const fs::path p = path_ / name;
    std::ofstream(p, std::ios::binary) << text;
    return p.string();
  }
  std::string file(const std::string& name) const { return (path_ / name).string(); }

 private:
  fs::path path_;
};

/// The message of the E that `f()` throws; a test failure and "" when it throws none.
template <class E, class F>
std::string error_message(F&& f) {
  try {
    f();
  } catch (const E& e) {
    return e.what();
  }
  ADD_FAILURE() << "no error";
  return "";
}

std::string read_text(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

// ---------------------------------------------------------------------------------------------
// The paper's scenarios.

struct PaperScenario {
  std::string file;
  std::string name;
  std::string channel;  ///< the stepped channel, also the scheduled parameter's stem
  double step_to;       ///< the scheduled setpoint value
  double z0;            ///< initial height [m]
  bool hover;
  double z_des;
  std::vector<Criterion> criteria;  ///< the paper: bands, in file order
  std::vector<Criterion> spec;      ///< the spec: bounds, in file order
};

std::vector<PaperScenario> paper_scenarios() {
  const auto none = std::nullopt;
  const std::vector<Criterion> attitude = {{"overshoot_pct", none, 2.0},
                                           {"t95_s", 3.5, 4.5},
                                           {"settling_time_2pct_s", 5.0, 7.0},
                                           {"steady_state_error_pct", none, 1.0}};
  const std::vector<Criterion> attitude_spec = {{"overshoot_pct", none, 10.0},
                                                {"t95_s", none, 5.0},
                                                {"settling_time_2pct_s", none, 8.0},
                                                {"steady_state_error_pct", none, 1.0}};
  return {
      {"altitude_step.yaml",
       "altitude_step",
       "z",
       10.0,
       0.0,
       false,
       0.0,
       {{"overshoot_pct", 15.0, 21.0},
        {"peak_time_s", 2.0, 3.0},
        {"settling_time_2pct_s", none, 8.5},
        {"steady_state_error_pct", none, 1.0}},
       {{"overshoot_pct", none, 25.0},
        {"t95_s", none, 5.0},
        {"settling_time_2pct_s", none, 10.0},
        {"steady_state_error_pct", none, 1.0}}},
      {"roll_step.yaml", "roll_step", "roll", 0.1, 10.0, true, 10.0, attitude, attitude_spec},
      {"pitch_step.yaml", "pitch_step", "pitch", 0.15, 10.0, true, 10.0, attitude, attitude_spec},
      {"yaw_step.yaml",
       "yaw_step",
       "yaw",
       0.2,
       10.0,
       true,
       10.0,
       {{"overshoot_pct", none, 2.0}, {"settling_time_2pct_s", 7.0, 9.0}, {"steady_state_error_pct", none, 1.0}},
       {{"overshoot_pct", none, 10.0},
        {"t95_s", none, 8.0},
        {"settling_time_2pct_s", none, 10.0},
        {"steady_state_error_pct", none, 1.0}}},
  };
}

class PaperScenarioTest : public ::testing::TestWithParam<PaperScenario> {};

TEST_P(PaperScenarioTest, LoadsWithTheDocumentedValues) {
  const PaperScenario& e = GetParam();
  const std::string path = (kSourceDir / "scenarios" / "paper" / e.file).string();
  const Scenario sc = load_scenario(path, hosts::test_resolvers());

  EXPECT_EQ(sc.path, path);
  EXPECT_EQ(sc.name, e.name);
  EXPECT_FALSE(sc.description.empty());

  // Rates: 100 Hz plant (10 ms), 50 Hz controller (every 2nd tick), 15 s = 1500 ticks.
  EXPECT_EQ(sc.simulation.plant.clock.period_ns, 10'000'000);
  EXPECT_EQ(sc.simulation.controller_divider, 2);
  EXPECT_EQ(sc.simulation.duration_ticks, 1500);
  EXPECT_EQ(sc.simulation.plant.substeps, 1);
  EXPECT_EQ(sc.simulation.plant.command_delay_ticks, 0);
  EXPECT_EQ(sc.simulation.ns, "/drone");

  // The paper's vehicle (Table 1), unchanged.
  const model::VehicleParams table1;
  EXPECT_EQ(sc.vehicle.mass_kg, table1.mass_kg);
  EXPECT_EQ(sc.vehicle.kt_N_per_rad2_s2, table1.kt_N_per_rad2_s2);
  EXPECT_EQ(sc.controller.vehicle.mass_kg, table1.mass_kg);
  EXPECT_EQ(controllers::paper_controller(sc.controller)->vehicle().mass_kg, table1.mass_kg);

  EXPECT_EQ(sc.initial.p_W, Eigen::Vector3d(0.0, 0.0, e.z0));
  EXPECT_EQ(sc.initial.yaw_rad, 0.0);
  EXPECT_EQ(sc.initial.hover, e.hover);

  EXPECT_EQ(sc.controller.node.setpoint.mode, control::Mode::kAttitude);
  EXPECT_EQ(sc.controller.node.setpoint.p_des_W.z(), e.z_des);
  EXPECT_EQ(sc.controller.node.setpoint.roll_des_rad, 0.0);
  EXPECT_EQ(sc.controller.node.setpoint.pitch_des_rad, 0.0);
  EXPECT_EQ(sc.controller.node.setpoint.yaw_des_rad, 0.0);

  // One scheduled change at t = 0: <channel>_des to the step value.
  ASSERT_EQ(sc.schedule.size(), 1u);
  EXPECT_EQ(sc.schedule[0].tick, 0);
  EXPECT_EQ(sc.schedule[0].name, e.channel + "_des");
  ASSERT_TRUE(std::holds_alternative<double>(sc.schedule[0].value));
  EXPECT_EQ(std::get<double>(sc.schedule[0].value), e.step_to);

  ASSERT_EQ(sc.steps.size(), 1u);
  const StepSpec& step = sc.steps[0];
  EXPECT_EQ(step.channel, e.channel);
  EXPECT_EQ(step.t_step_s, 0.0);
  // The spec bounds first, then the paper's bands, each in file order.
  ASSERT_EQ(step.criteria.size(), e.spec.size() + e.criteria.size());
  for (std::size_t i = 0; i < step.criteria.size(); ++i) {
    const bool spec = i < e.spec.size();
    const Criterion& want = spec ? e.spec[i] : e.criteria[i - e.spec.size()];
    SCOPED_TRACE(want.figure);
    EXPECT_EQ(step.criteria[i].set, spec ? CriteriaSet::kSpec : CriteriaSet::kPaper);
    EXPECT_EQ(step.criteria[i].figure, want.figure);
    EXPECT_EQ(step.criteria[i].min, want.min);
    EXPECT_EQ(step.criteria[i].max, want.max);
  }
  EXPECT_NE(step.reference_source.find("paper"), std::string::npos);
  EXPECT_TRUE(step.reference.count("settling_time_2pct_s"));
  EXPECT_FALSE(step.reference.count("source"));  // the source is text, not a figure
}

INSTANTIATE_TEST_SUITE_P(Paper, PaperScenarioTest, ::testing::ValuesIn(paper_scenarios()),
                         [](const auto& info) { return info.param.name; });

TEST(ScenarioTest, AltitudeStepReferenceFigures) {
  const Scenario sc =
      load_scenario((kSourceDir / "scenarios/paper/altitude_step.yaml").string(), hosts::test_resolvers());
  ASSERT_EQ(sc.steps.size(), 1u);
  const std::map<std::string, double> expected = {
      {"overshoot_pct", 18.0}, {"peak_time_s", 2.5}, {"settling_time_2pct_s", 8.0}};
  EXPECT_EQ(sc.steps[0].reference, expected);
  EXPECT_EQ(sc.steps[0].reference_source, "paper, Sec. IV-ii and Fig. 4");
}

TEST(ScenarioTest, EmptyMappingGivesTheDefaults) {
  TempDir dir;
  const std::string path = dir.write("minimal.yaml", "name: minimal\n");
  const Scenario sc = load_scenario(path, hosts::test_resolvers());
  EXPECT_EQ(sc.name, "minimal");
  EXPECT_EQ(sc.simulation.plant.clock.period_ns, 10'000'000);
  EXPECT_EQ(sc.simulation.controller_divider, 2);
  EXPECT_EQ(sc.simulation.duration_ticks, 1500);
  EXPECT_TRUE(sc.schedule.empty());
  EXPECT_TRUE(sc.steps.empty());

  // Without a name, the file's stem.
  EXPECT_EQ(load_scenario(dir.write("unnamed.yaml", "description: x\n"), hosts::test_resolvers()).name, "unnamed");
}

// The extra sensors' keys in their units (uT, deg, Pa, m), in SI in the configuration; what is not
// given keeps the model's default exactly; environment.site reaches the barometer and the GNSS.
TEST(ScenarioTest, ExtraSensorKeysAreReadInTheirUnits) {
  TempDir dir;
  const Scenario sc = load_scenario(dir.write("sensors.yaml",
                                              "environment:\n"
                                              "  site: {latitude_deg: 47.5, longitude_deg: 8.25, altitude_m: 420}\n"
                                              "sensors:\n"
                                              "  magnetometer: {rate_hz: 50, field_uT: 48, declination_deg: 2.5,\n"
                                              "                 hard_iron_uT: [2, -1.5, 0.8]}\n"
                                              "  barometer: {noise_sigma_Pa: 3, latency_ticks: 2}\n"
                                              "  gnss: {rate_hz: 5, vertical_sigma_m: 1.5}\n"),
                                    hosts::test_resolvers());
  const sensors::SensorSet& s = sc.simulation.plant.realism.extra_sensors;
  ASSERT_TRUE(s.magnetometer && s.barometer && s.gnss);
  const sensors::MagnetometerConfig defaults_m;
  EXPECT_EQ(s.magnetometer->timing.divider, 2);  // 100 Hz plant / 50 Hz
  EXPECT_DOUBLE_EQ(s.magnetometer->field_T, 48e-6);
  EXPECT_DOUBLE_EQ(s.magnetometer->declination_rad, 2.5 * 3.14159265358979323846 / 180.0);
  EXPECT_EQ(s.magnetometer->inclination_rad, defaults_m.inclination_rad);  // not given: the default
  EXPECT_EQ(s.magnetometer->noise_sigma_T, 0.0);
  EXPECT_DOUBLE_EQ(s.magnetometer->hard_iron_T.x(), 2e-6);
  EXPECT_DOUBLE_EQ(s.magnetometer->hard_iron_T.y(), -1.5e-6);
  EXPECT_DOUBLE_EQ(s.magnetometer->hard_iron_T.z(), 0.8e-6);
  EXPECT_EQ(s.barometer->timing.divider, 2);  // its default 50 Hz
  EXPECT_EQ(s.barometer->timing.latency_ticks, 2);
  EXPECT_EQ(s.barometer->noise_sigma_Pa, 3.0);
  EXPECT_EQ(s.barometer->sea_level_pressure_Pa, sensors::BarometerConfig{}.sea_level_pressure_Pa);
  EXPECT_EQ(s.barometer->site_altitude_m, 420.0);
  EXPECT_EQ(s.gnss->timing.divider, 20);  // 100 Hz / 5 Hz
  EXPECT_EQ(s.gnss->vertical_sigma_m, 1.5);
  EXPECT_EQ(s.gnss->horizontal_sigma_m, 0.0);
  EXPECT_DOUBLE_EQ(s.gnss->site.latitude_rad, 47.5 * 3.14159265358979323846 / 180.0);
  EXPECT_DOUBLE_EQ(s.gnss->site.longitude_rad, 8.25 * 3.14159265358979323846 / 180.0);
  EXPECT_EQ(s.gnss->site.height_m, 420.0);
  // A key out of its range is named with its range, in the key's unit.
  const std::string range = error_message<std::exception>([&] {
    load_scenario(dir.write("bad.yaml", "sensors:\n  magnetometer: {field_uT: 500}\n"), hosts::test_resolvers());
  });
  EXPECT_THAT(range, HasSubstr("sensors.magnetometer.field_uT"));
  EXPECT_THAT(range, HasSubstr("100"));
  // The GNSS outage: both ends read in seconds; a window that ends before it starts is named.
  const Scenario outage = load_scenario(
      dir.write("outage.yaml", "sensors:\n  gnss: {outage_from_s: 4, outage_to_s: 6.5}\n"), hosts::test_resolvers());
  EXPECT_EQ(outage.simulation.plant.realism.extra_sensors.gnss->outage_from_s, 4.0);
  EXPECT_EQ(outage.simulation.plant.realism.extra_sensors.gnss->outage_to_s, 6.5);
  EXPECT_THAT(
      [&] {
        load_scenario(dir.write("backwards.yaml", "sensors:\n  gnss: {outage_from_s: 6, outage_to_s: 4}\n"),
                      hosts::test_resolvers());
      },
      ThrowsMessage<std::runtime_error>(
          HasSubstr("sensors.gnss: outage_to_s (4.000000 s) is not after outage_from_s")));
}

TEST(ScenarioTest, ScheduleTimesBecomeTicks) {
  TempDir dir;
  const std::string path =
      dir.write("sched.yaml", R"(simulation: {plant_rate_hz: 200, controller_rate_hz: 50, duration_s: 3}
schedule:
  - at_s: 0.5
    set: {z_des: 2, altitude: {kp: 5}}
  - at_s: 1.25
    set: {mode: position}
)");
  const Scenario sc = load_scenario(path, hosts::test_resolvers());
  EXPECT_EQ(sc.simulation.plant.clock.period_ns, 5'000'000);
  EXPECT_EQ(sc.simulation.controller_divider, 4);
  EXPECT_EQ(sc.simulation.duration_ticks, 600);
  ASSERT_EQ(sc.schedule.size(), 3u);
  EXPECT_EQ(sc.schedule[0].tick, 100);
  EXPECT_EQ(sc.schedule[0].name, "z_des");
  EXPECT_EQ(std::get<double>(sc.schedule[0].value), 2.0);
  EXPECT_EQ(sc.schedule[1].tick, 100);
  EXPECT_EQ(sc.schedule[1].name, "altitude.kp");
  EXPECT_EQ(std::get<double>(sc.schedule[1].value), 5.0);
  EXPECT_EQ(sc.schedule[2].tick, 250);
  EXPECT_EQ(sc.schedule[2].name, "mode");
  EXPECT_EQ(std::get<std::string>(sc.schedule[2].value), "position");
  // Scheduled values do not change the initial configuration.
  EXPECT_EQ(sc.controller.node.setpoint.p_des_W.z(), 0.0);
  EXPECT_EQ(paper_params(sc.controller).altitude.kp, kPaperDefaults.altitude.kp);
}

TEST(ScenarioTest, NestedAndDottedControllerKeysAreEquivalent) {
  TempDir dir;
  const Scenario nested = load_scenario(dir.write("nested.yaml", R"(controller:
  mode: position
  altitude: {kp: 5.5, kd: 3.25}
  lqr:
    roll: {q_angle: 2.0, r: 50}
    yaw: {q_rate: 7}
  position: {max_tilt: 0.3}
schedule:
  - at_s: 1
    set:
      lqr: {pitch: {q_angle: 4}}
)"),
                                        hosts::test_resolvers());
  const Scenario dotted = load_scenario(dir.write("dotted.yaml", R"(controller:
  mode: position
  altitude.kp: 5.5
  altitude.kd: 3.25
  lqr.roll.q_angle: 2.0
  lqr.roll.r: 50
  lqr.yaw.q_rate: 7
  position.max_tilt: 0.3
schedule:
  - at_s: 1
    set: {lqr.pitch.q_angle: 4}
)"),
                                        hosts::test_resolvers());
  const Scenario mixed = load_scenario(dir.write("mixed.yaml", R"(controller:
  mode: position
  altitude: {kp: 5.5}
  altitude.kd: 3.25
  lqr: {roll.q_angle: 2.0, roll: {r: 50}, yaw.q_rate: 7}
  position.max_tilt: 0.3
schedule:
  - at_s: 1
    set: {lqr.pitch: {q_angle: 4}}
)"),
                                       hosts::test_resolvers());
  for (const Scenario* sc : {&nested, &dotted, &mixed}) {
    SCOPED_TRACE(sc->path);
    const auto& p = paper_params(sc->controller);
    EXPECT_EQ(sc->controller.node.setpoint.mode, control::Mode::kPosition);
    EXPECT_EQ(p.altitude.kp, 5.5);
    EXPECT_EQ(p.altitude.kd, 3.25);
    EXPECT_EQ(p.roll.q_angle, 2.0);
    EXPECT_EQ(p.roll.r, 50.0);
    EXPECT_EQ(p.yaw.q_rate, 7.0);
    EXPECT_EQ(p.position.max_tilt_rad, 0.3);
    EXPECT_EQ(p.pitch.q_angle, kPaperDefaults.pitch.q_angle);
    ASSERT_EQ(sc->schedule.size(), 1u);
    EXPECT_EQ(sc->schedule[0].tick, 100);
    EXPECT_EQ(sc->schedule[0].name, "lqr.pitch.q_angle");
    EXPECT_EQ(std::get<double>(sc->schedule[0].value), 4.0);
  }
}

// Gains in a type's section apply when that type flies and are checked, but not used, when another does;
// what is flown (the node's mode and setpoints) is the same for every type.
TEST(ScenarioTest, TypeSectionsHoldEachControllersGains) {
  TempDir dir;
  const std::string file = dir.write("typed.yaml", R"(controller:
  mode: position
  z_des: 4
  paper:
    lqr: {roll: {q_angle: 2.0}}
    position.kp: 0.9
  se3:
    k_x.x: 7.5
schedule:
  - at_s: 1
    set: {z_des: 6, paper: {position.kd: 1.1}, se3: {k_v.x: 2.5}}
)");
  const Scenario paper = load_scenario(file, hosts::test_resolvers());
  EXPECT_EQ(paper.controller.type(), "paper");
  EXPECT_EQ(paper_params(paper.controller).roll.q_angle, 2.0);
  EXPECT_EQ(paper_params(paper.controller).position.kp, 0.9);
  const Scenario se3 = load_scenario(file, "se3", hosts::test_resolvers());
  EXPECT_EQ(se3.controller.type(), "se3");
  EXPECT_EQ(std::get<double>(*control::get_parameter(se3.controller, "k_x.x")), 7.5);
  for (const Scenario* sc : {&paper, &se3}) {
    SCOPED_TRACE(sc->controller.type());
    EXPECT_EQ(sc->controller.node.setpoint.mode, control::Mode::kPosition);
    EXPECT_EQ(sc->controller.node.setpoint.p_des_W.z(), 4.0);
    // The schedule holds the node's change and the flying type's gain only.
    ASSERT_EQ(sc->schedule.size(), 2u);
    EXPECT_EQ(sc->schedule[0].name, "z_des");
    EXPECT_EQ(sc->schedule[1].name, sc == &paper ? "position.kd" : "k_v.x");
  }
  // A typo in the gains of a type that does not fly is still an error, named at its key.
  const std::string typo = dir.write("typo.yaml", "controller:\n  paper:\n    lqr: {roll: {q_angel: 2}}\n");
  EXPECT_THAT(error_message<ConfigError>([&] { (void)load_scenario(typo, "se3", hosts::test_resolvers()); }),
              HasSubstr("controller.paper.lqr.roll.q_angel: unknown parameter 'lqr.roll.q_angel'"));
  // The node's parameters belong to what is flown, not to a type's gains.
  const std::string node = dir.write("node.yaml", "controller:\n  se3: {z_des: 3}\n");
  EXPECT_THAT(error_message<ConfigError>([&] { (void)load_scenario(node, hosts::test_resolvers()); }),
              HasSubstr("controller.se3.z_des: 'z_des' is the node's"));
}

// A file that writes the paper controller's gains directly under controller: (the older form) flies
// any other type: --controller moves them into the paper section, where they are checked and unused.
TEST(ScenarioTest, AnotherTypeTakesTheFilesFlatGainsAsThePaperControllers) {
  TempDir dir;
  const std::string file = dir.write("flat.yaml", R"(controller:
  mode: position
  z_des: 2
  lqr: {roll: {q_angle: 3.0}}
  position: {kp: 0.7}
)");
  EXPECT_EQ(paper_params(load_scenario(file, hosts::test_resolvers()).controller).roll.q_angle, 3.0);
  const Scenario se3 = load_scenario(file, "se3", hosts::test_resolvers());
  EXPECT_EQ(se3.controller.type(), "se3");
  EXPECT_EQ(se3.controller.node.setpoint.p_des_W.z(), 2.0);
  YAML::Node root = YAML::LoadFile(file);
  set_controller_type(root, "se3");
  EXPECT_EQ(root["controller"]["type"].as<std::string>(), "se3");
  EXPECT_FALSE(root["controller"]["lqr"]);
  EXPECT_EQ(root["controller"]["paper"]["lqr"]["roll"]["q_angle"].as<double>(), 3.0);
  EXPECT_EQ(root["controller"]["paper"]["position"]["kp"].as<double>(), 0.7);
  EXPECT_EQ(root["controller"]["z_des"].as<double>(), 2.0);
  // Back to paper: the moved gains apply again, from their section.
  set_controller_type(root, "paper");
  EXPECT_EQ(paper_params(load_scenario(root, file, hosts::test_resolvers()).controller).roll.q_angle, 3.0);
}

TEST(ScenarioTest, ControllerChoicesAreParsedOrRefusedWithWhatWasExpected) {
  EXPECT_EQ(parse_controller_choice("se3").kind, ControllerChoice::Kind::kType);
  const ControllerChoice py = parse_controller_choice("python:my_controllers:LevelPD");
  EXPECT_EQ(py.kind, ControllerChoice::Kind::kPython);
  EXPECT_EQ(py.target, "my_controllers:LevelPD");
  EXPECT_THAT([] { (void)parse_controller_choice("python:nocolon"); },
              ThrowsMessage<std::invalid_argument>(HasSubstr("expected python:MODULE:CLASS")));
  EXPECT_THAT([] { (void)parse_controller_choice("fmu:/no/such.fmu"); },
              ThrowsMessage<std::invalid_argument>(HasSubstr("no such file '/no/such.fmu'")));
  EXPECT_THAT([] { (void)parse_controller_choice("cascade"); },
              ThrowsMessage<std::invalid_argument>(HasSubstr("expected a controller type (paper, ")));
}

TEST(ScenarioTest, VehicleSectionIsReadAndReachesTheController) {
  TempDir dir;
  const Scenario sc = load_scenario(dir.write("vehicle.yaml", R"(vehicle:
  mass_kg: 2.5
  layout: x
  spin: [-1, 1, -1, 1]
  motor: {model: first_order, tau_up_s: 0.03}
)"),
                                    hosts::test_resolvers());
  EXPECT_EQ(sc.vehicle.mass_kg, 2.5);
  EXPECT_EQ(sc.vehicle.layout, model::RotorLayout::kX);
  EXPECT_EQ((std::array<int, 4>{sc.vehicle.spin[0], sc.vehicle.spin[1], sc.vehicle.spin[2], sc.vehicle.spin[3]}),
            (std::array<int, 4>{-1, 1, -1, 1}));
  EXPECT_EQ(sc.vehicle.motor.model, model::MotorModel::kFirstOrder);
  EXPECT_EQ(sc.vehicle.motor.tau_up_s, 0.03);
  EXPECT_EQ(sc.controller.vehicle.mass_kg, 2.5);
  EXPECT_EQ(controllers::paper_controller(sc.controller)->vehicle().mass_kg, 2.5);
}

// `preset:` starts from a ready vehicle; the section's other keys override single values, in a
// scenario and in a vehicle file alike; the controller is designed for the result.
TEST(ScenarioTest, VehiclePresetIsReadAndOverridden) {
  TempDir dir;
  const Scenario sc = load_scenario(dir.write("preset.yaml", R"(vehicle:
  preset: crazyflie2
  mass_kg: 0.03
  motor: {model: first_order, tau_up_s: 0.01, tau_down_s: 0.01}
controller: {type: se3}
)"),
                                    hosts::test_resolvers());
  EXPECT_EQ(sc.vehicle.mass_kg, 0.03);  // overridden
  EXPECT_EQ(sc.vehicle.motor.model, model::MotorModel::kFirstOrder);
  EXPECT_EQ(sc.vehicle.Ixx_kg_m2, 16.571710e-6);  // from Förster's tensor
  EXPECT_EQ(sc.vehicle.Iyz_kg_m2, 1.800197e-6);
  EXPECT_EQ(sc.vehicle.layout, model::RotorLayout::kX);
  EXPECT_EQ(sc.vehicle.motor.omega_max_rad_s, 2618.0);
  EXPECT_EQ(sc.controller.vehicle.mass_kg, 0.03);
  // se3's position gain scaled to the overriding mass: k_x / m as for Table 1 (12.25 N/m / 1.96 kg).
  EXPECT_NEAR(std::get<double>(*sc.controller.controller->get_parameter("k_x.x")), 0.03 * 12.25 / 1.96, 1e-15);

  const model::VehicleParams f = load_vehicle(dir.write("f450.yaml", "preset: f450\nIzz_kg_m2: 0.04\n"));
  EXPECT_EQ(f.mass_kg, 1.4);
  EXPECT_EQ(f.kt_N_per_rad2_s2, 1.105e-5);
  EXPECT_EQ(f.Izz_kg_m2, 0.04);

  const std::string unknown =
      error_message<ConfigError>([&] { load_vehicle(dir.write("bad.yaml", "preset: crazyflie\n")); });
  EXPECT_THAT(unknown, HasSubstr("preset"));
  EXPECT_THAT(unknown, HasSubstr("crazyflie2"));  // the known names, or the nearest
}

// Every key of the vehicle parameter table, at its place in the file, reaches its member.
TEST(ScenarioTest, VehicleFileReadsEveryKey) {
  TempDir dir;
  const model::VehicleParams v = load_vehicle(dir.write("all.yaml", R"(mass_kg: 1.5
gravity_m_s2: 3.7
Ixx_kg_m2: 0.011
Iyy_kg_m2: 0.012
Izz_kg_m2: 0.021
Ixy_kg_m2: 0.001
Ixz_kg_m2: -0.0005
Iyz_kg_m2: 0.0002
arm_length_m: 0.25
kt_N_per_rad2_s2: 3.0e-7
km_Nm_per_rad2_s2: 2.0e-9
layout: x
spin: [-1, 1, -1, 1]
gyroscopic: simplified
motor:
  model: first_order
  tau_up_s: 0.015
  tau_down_s: 0.025
  omega_min_rad_s: 100
  omega_max_rad_s: 9000
aero:
  linear_drag_N_s_m: [0.1, 0.2, 0.3]
  quadratic_drag_N_s2_m2: [0.01, 0.02, 0.03]
  rotor_drag_N_s_m_per_rad_s: 1.0e-5
  ground_effect_rotor_radius_m: 0.12
  rotor_aero: true
  inflow_k_z: 2.0e-4
  flapping_k_flap: 3.0e-6
  translational_lift_k_h: 0.02
)"));
  EXPECT_EQ(v.mass_kg, 1.5);
  EXPECT_EQ(v.gravity_m_s2, 3.7);
  EXPECT_EQ(v.Ixx_kg_m2, 0.011);
  EXPECT_EQ(v.Iyy_kg_m2, 0.012);
  EXPECT_EQ(v.Izz_kg_m2, 0.021);
  EXPECT_EQ(v.Ixy_kg_m2, 0.001);
  EXPECT_EQ(v.Ixz_kg_m2, -0.0005);
  EXPECT_EQ(v.Iyz_kg_m2, 0.0002);
  EXPECT_EQ(v.arm_length_m, 0.25);
  EXPECT_EQ(v.kt_N_per_rad2_s2, 3.0e-7);
  EXPECT_EQ(v.km_Nm_per_rad2_s2, 2.0e-9);
  EXPECT_EQ(v.layout, model::RotorLayout::kX);
  EXPECT_EQ((std::array<int, 4>{v.spin[0], v.spin[1], v.spin[2], v.spin[3]}), (std::array<int, 4>{-1, 1, -1, 1}));
  EXPECT_EQ(v.gyroscopic, model::GyroscopicModel::kSimplified);
  EXPECT_EQ(v.motor.model, model::MotorModel::kFirstOrder);
  EXPECT_EQ(v.motor.tau_up_s, 0.015);
  EXPECT_EQ(v.motor.tau_down_s, 0.025);
  EXPECT_EQ(v.motor.omega_min_rad_s, 100.0);
  EXPECT_EQ(v.motor.omega_max_rad_s, 9000.0);
  EXPECT_EQ(v.aero.linear_drag_N_s_m, Eigen::Vector3d(0.1, 0.2, 0.3));
  EXPECT_EQ(v.aero.quadratic_drag_N_s2_m2, Eigen::Vector3d(0.01, 0.02, 0.03));
  EXPECT_EQ(v.aero.rotor_drag_N_s_m_per_rad_s, 1.0e-5);
  EXPECT_EQ(v.aero.ground_effect_rotor_radius_m, 0.12);
  EXPECT_EQ(v.aero.rotor_aero, model::RotorAero::kOn);
  EXPECT_EQ(v.aero.inflow_k_z, 2.0e-4);
  EXPECT_EQ(v.aero.flapping_k_flap, 3.0e-6);
  EXPECT_EQ(v.aero.translational_lift_k_h, 0.02);
  // The hub drag beside the lumped rotor drag is the same drag twice: refused at the lumped key.
  EXPECT_THAT(
      error_message<ConfigError>([&] {
        load_vehicle(dir.write("twice.yaml",
                               "aero: {rotor_aero: true, rotor_drag_k_d: 1e-5, rotor_drag_N_s_m_per_rad_s: 1e-5}\n"));
      }),
      HasSubstr("rotor_drag_N_s_m_per_rad_s"));
}

// ---------------------------------------------------------------------------------------------
// Malformed scenarios: each error names the file, the key path and the bad value.

struct BadScenario {
  std::string label;
  std::string yaml;
  std::vector<std::string> must_mention;  ///< besides the file name
};

class BadScenarioTest : public ::testing::TestWithParam<BadScenario> {};

TEST_P(BadScenarioTest, ConfigErrorNamesFileKeyAndValue) {
  const BadScenario& b = GetParam();
  TempDir dir;
  const std::string path = dir.write(b.label + ".yaml", b.yaml);
  const std::string msg = error_message<ConfigError>([&] { load_scenario(path, hosts::test_resolvers()); });
  EXPECT_THAT(msg, StartsWith(path + ": ")) << "for\n" << b.yaml;
  for (const std::string& s : b.must_mention) EXPECT_THAT(msg, HasSubstr(s));
}

INSTANTIATE_TEST_SUITE_P(
    Scenario, BadScenarioTest,
    ::testing::Values(
        BadScenario{"unknown_top_level_key", "name: x\nsimulaton: {duration_s: 1}\n", {"simulaton: unknown key"}},
        BadScenario{"unknown_limit",
                    "simulation: {duration_s: 5}\nanalysis:\n  limits: {max_sat_s: 1}\n",
                    {"analysis.limits.max_sat_s: unknown key"}},
        BadScenario{"negative_limit",
                    "simulation: {duration_s: 5}\nanalysis:\n  limits: {max_saturated_s: -1}\n",
                    {"analysis.limits.max_saturated_s: ", "'-1'"}},
        BadScenario{"string_limit",
                    "analysis:\n  limits: {max_rms_u1_deviation_n: lots}\n",
                    {"analysis.limits.max_rms_u1_deviation_n: ", "'lots'", "expected a number"}},
        BadScenario{"unknown_nested_key", "vehicle:\n  mas_kg: 2\n", {"vehicle.mas_kg: unknown key"}},
        BadScenario{
            "unknown_motor_key", "vehicle:\n  motor: {tau_upp_s: 0.1}\n", {"vehicle.motor.tau_upp_s: unknown key"}},
        BadScenario{"string_for_number",
                    "simulation:\n  plant_rate_hz: fast\n",
                    {"simulation.plant_rate_hz: ", "'fast'", "expected a number"}},
        BadScenario{"list_for_number",
                    "simulation:\n  duration_s: [1, 2]\n",
                    {"simulation.duration_s: ", "a list", "expected a number"}},
        BadScenario{"negative_mass", "vehicle: {mass_kg: -1}\n", {"vehicle.mass_kg: ", "'-1'"}},
        BadScenario{"motor_lag_too_fast_for_step",
                    "vehicle:\n  motor: {model: first_order, tau_up_s: 0.002}\nsimulation: {substeps: 1}\n",
                    {"simulation.substeps: ", "0.002", "at least 3 substeps"}},
        BadScenario{"rate_not_a_divisor",
                    "simulation: {plant_rate_hz: 100, controller_rate_hz: 30}\n",
                    {"simulation.controller_rate_hz: ", "30", "divisor"}},
        BadScenario{"controller_faster_than_plant",
                    "simulation: {plant_rate_hz: 100, controller_rate_hz: 200}\n",
                    {"simulation.controller_rate_hz: ", "200"}},
        BadScenario{
            "duration_not_on_a_tick", "simulation: {duration_s: 1.005}\n", {"simulation.duration_s: ", "1.005"}},
        BadScenario{"schedule_time_not_on_a_tick",
                    "schedule:\n  - at_s: 0.0125\n    set: {z_des: 1}\n",
                    {"schedule[0].at_s: ", "0.0125", "whole number of plant periods"}},
        BadScenario{"schedule_time_after_the_end",
                    "simulation: {duration_s: 2}\nschedule:\n  - at_s: 0\n    set: {z_des: 1}\n"
                    "  - at_s: 3\n    set: {z_des: 2}\n",
                    {"schedule[1].at_s: ", "'3'"}},
        BadScenario{"schedule_without_set", "schedule:\n  - at_s: 1\n", {"schedule[0].set: "}},
        BadScenario{"schedule_unknown_parameter",
                    "schedule:\n  - at_s: 1\n    set: {z_dse: 1}\n",
                    {"schedule[0].set.z_dse: ", "z_dse"}},
        BadScenario{"unknown_controller_parameter",
                    "controller:\n  z_dse: 3\n",
                    {"controller.z_dse: ", "unknown parameter 'z_dse' of the node or of controller type 'paper'"}},
        BadScenario{"unknown_nested_controller_parameter",
                    "controller:\n  altitude: {kq: 3}\n",
                    {"controller.altitude.kq: ", "'altitude.kq'"}},
        BadScenario{"parameter_out_of_range",
                    "controller:\n  roll_des: 5\n",
                    {"controller.roll_des: ", "got 5", "[-1.5, 1.5]"}},
        BadScenario{"parameter_not_a_number",
                    "controller:\n  altitude.kp: strong\n",
                    {"controller.altitude.kp: ", "'strong'", "number"}},
        BadScenario{
            "bad_choice", "controller:\n  mode: hover\n", {"controller.mode: ", "'hover'", "'attitude'", "'position'"}},
        BadScenario{"bad_layout", "vehicle: {layout: h}\n", {"vehicle.layout: ", "'h'", "'plus'"}},
        BadScenario{"spin_not_unit", "vehicle:\n  spin: [1, -1, 2, -1]\n", {"vehicle.spin: ", "2"}},
        BadScenario{"spin_unbalanced", "vehicle:\n  spin: [1, 1, 1, -1]\n", {"vehicle.spin: ", "[1, 1, 1, -1]"}},
        BadScenario{"gravity_zero", "vehicle: {gravity_m_s2: 0}\n", {"vehicle.gravity_m_s2: ", "got '0'", "(0, 1000]"}},
        BadScenario{"mass_below_range", "vehicle: {mass_kg: 1e-9}\n", {"vehicle.mass_kg: ", "[1e-06, 1e+12]"}},
        BadScenario{"drag_entry_negative",
                    "vehicle:\n  aero: {linear_drag_N_s_m: [0, -0.5, 0]}\n",
                    {"vehicle.aero.linear_drag_N_s_m: ", "-0.5", "[0, 1e+06]"}},
        BadScenario{"omega_min_above_max",
                    "vehicle:\n  motor: {omega_min_rad_s: 500, omega_max_rad_s: 400}\n",
                    {"vehicle.motor.omega_min_rad_s: ", "below motor.omega_max_rad_s", "500"}},
        BadScenario{
            "unknown_aero_key", "vehicle:\n  aero: {sideways_drag: 1}\n", {"vehicle.aero.sideways_drag: unknown key"}},
        BadScenario{"spin_too_short", "vehicle:\n  spin: [1, -1]\n", {"vehicle.spin: ", "a list", "4"}},
        BadScenario{
            "initial_below_ground", "initial: {position_m: [0, 0, -1]}\n", {"initial.position_m: ", "z must be >= 0"}},
        BadScenario{"unknown_step_channel",
                    "analysis:\n  steps:\n    - {channel: altitude, at_s: 0}\n",
                    {"analysis.steps[0].channel: ", "'altitude'"}},
        BadScenario{"unknown_step_figure",
                    "analysis:\n  steps:\n    - channel: z\n      criteria: {overshoot: [0, 1]}\n",
                    {"analysis.steps[0].criteria.overshoot: "}},
        BadScenario{"criterion_not_a_pair",
                    "analysis:\n  steps:\n    - channel: z\n      criteria: {overshoot_pct: 5}\n",
                    {"analysis.steps[0].criteria.overshoot_pct: ", "[min, max]"}},
        BadScenario{"criterion_bound_not_a_number",
                    "analysis:\n  steps:\n    - channel: z\n      criteria: {overshoot_pct: [0, lots]}\n",
                    {"analysis.steps[0].criteria.overshoot_pct: ", "'lots'"}},
        BadScenario{"criterion_min_above_max",
                    "analysis:\n  steps:\n    - channel: z\n      criteria: {t95_s: [3, 1]}\n",
                    {"analysis.steps[0].criteria.t95_s: ", "min is above max"}},
        // criteria is the old name of spec: both in one block cannot say which bands were meant.
        BadScenario{"criteria_beside_spec",
                    "analysis:\n  steps:\n    - channel: z\n      criteria: {t95_s: [null, 5]}\n"
                    "      spec: {t95_s: [null, 4]}\n",
                    {"analysis.steps[0].criteria: ", "given beside spec", "keep one of the two keys"}},
        BadScenario{"criteria_beside_spec_in_hold",
                    "analysis:\n  hold:\n    criteria: {max_vertical_error_m: [null, 1]}\n"
                    "    spec: {max_vertical_error_m: [null, 1]}\n",
                    {"analysis.hold.criteria: ", "given beside spec"}},
        BadScenario{"unknown_paper_figure",
                    "analysis:\n  steps:\n    - channel: z\n      paper: {overshoot: [0, 1]}\n",
                    {"analysis.steps[0].paper.overshoot: ", "unknown step figure", "overshoot_pct"}},
        BadScenario{"hold_without_bands", "analysis:\n  hold: {after_s: 1}\n", {"analysis.hold.spec: ", "missing"}},
        BadScenario{"limits_flat_beside_sets",
                    "analysis:\n  limits:\n    max_saturated_s: 1\n    paper: {max_saturated_s: 0}\n",
                    {"analysis.limits.max_saturated_s: ", "beside spec/paper"}},
        BadScenario{"top_level_not_a_mapping", "- 1\n- 2\n", {"mapping"}},
        BadScenario{"section_not_a_mapping", "simulation: 100\n", {"simulation: ", "'100'", "mapping"}},
        // Found by fuzz_config (tests/fuzz/corpus/fuzz_config/regression_*): a list or a mapping as a
        // key threw yaml-cpp's conversion error past the loader; an alias containing itself made the
        // parameter walk recurse until the stack overflowed.
        BadScenario{"list_as_key", "? [a, b]\n: 1\n", {"a list as a key", "expected a plain name"}},
        BadScenario{
            "mapping_as_controller_key", "controller:\n  ? {a: 1}\n  : 2\n", {"controller: ", "a mapping as a key"}},
        BadScenario{"alias_containing_itself",
                    "controller: &c\n  lqr: *c\n",
                    {"controller.lqr.lqr.lqr: ", "nested too deeply"}},
        BadScenario{"criterion_bound_a_list",
                    "analysis:\n  steps:\n    - channel: z\n      criteria: {overshoot_pct: [[1], 2]}\n",
                    {"analysis.steps[0].criteria.overshoot_pct: ", "got a list, expected a number or null"}},
        BadScenario{"parameter_a_list",
                    "controller:\n  z_des: [1, 2]\n",
                    {"controller.z_des: ", "got a list, expected a single value"}},
        // A number or boolean in quotes is YAML text: refused where a number (or true/false) belongs,
        // with the value as written.
        BadScenario{"quoted_mass",
                    "vehicle: {mass_kg: \"1.2\"}\n",
                    {"vehicle.mass_kg: \"1.2\" is a string; write 1.2 without quotes"}},
        BadScenario{"single_quoted_duration",
                    "simulation: {duration_s: '10'}\n",
                    {"simulation.duration_s: \"10\" is a string; write 10 without quotes"}},
        BadScenario{"str_tagged_rate",
                    "simulation: {plant_rate_hz: !!str 100}\n",
                    {"simulation.plant_rate_hz: \"100\" is a string"}},
        BadScenario{"quoted_integer", "simulation: {substeps: \"4\"}\n", {"simulation.substeps: \"4\" is a string"}},
        BadScenario{"quoted_list_entry",
                    "initial: {position_m: [0, \"1\", 2]}\n",
                    {"initial.position_m: \"1\" is a string; write 1 without quotes"}},
        BadScenario{"quoted_controller_parameter",
                    "controller:\n  altitude.kp: \"4\"\n",
                    {"controller.altitude.kp: \"4\" is a string; write 4 without quotes"}},
        BadScenario{"quoted_criterion_bound",
                    "analysis:\n  steps:\n    - channel: z\n      spec: {t95_s: [null, \"5\"]}\n",
                    {"analysis.steps[0].spec.t95_s: \"5\" is a string"}},
        BadScenario{"quoted_realism_number",
                    "sensors:\n  pose: {position_sigma_m: \"0.01\"}\n",
                    {"sensors.pose.position_sigma_m: \"0.01\" is a string"}},
        // An unknown key or parameter names the nearest known one when one is close.
        BadScenario{
            "misspelt_section", "simulaton: {duration_s: 1}\n", {"simulaton: unknown key; did you mean 'simulation'?"}},
        BadScenario{"misspelt_vehicle_key", "vehicle: {mas_kg: 2}\n", {"did you mean 'mass_kg'?"}},
        BadScenario{"unit_left_off", "simulation: {duration: 2}\n", {"did you mean 'duration_s'?"}},
        BadScenario{"misspelt_gain", "controller:\n  altitude: {kq: 3}\n", {"did you mean 'altitude.kp'?"}},
        BadScenario{"swapped_letters",
                    "controller: {paper: {lqr: {roll: {q_angel: 2}}}}\n",
                    {"did you mean 'lqr.roll.q_angle'?"}},
        BadScenario{"misspelt_figure",
                    "analysis:\n  steps:\n    - channel: z\n      spec: {overshot_pct: [0, 1]}\n",
                    {"unknown step figure", "did you mean 'overshoot_pct'?"}},
        BadScenario{"misspelt_realism_key",
                    "sensors:\n  pose: {positon_sigma_m: 0.01}\n",
                    {"sensors.pose.positon_sigma_m: unknown key; did you mean 'position_sigma_m'?"}},
        BadScenario{"misspelt_controller_type",
                    "controller: {type: se4}\n",
                    {"controller.type: ", "'se4'", "did you mean 'se3'?"}},
        BadScenario{"yaml_syntax_error",
                    "name: broken\nsimulation:\n  plant_rate_hz: 100\n  duration_s: 15: 3\n"
                    "controller:\n  mode: attitude\n",
                    {"line 4", "YAML syntax error"}}),
    [](const auto& info) { return info.param.label; });

TEST(ScenarioTest, MissingFileIsAConfigErrorNamingIt) {
  TempDir dir;
  const std::string path = dir.file("does_not_exist.yaml");
  EXPECT_THAT(error_message<ConfigError>([&] { load_scenario(path, hosts::test_resolvers()); }), HasSubstr(path));
}

TEST(ScenarioTest, VehicleAndControllerFilesUseTheSameChecks) {
  TempDir dir;
  const model::VehicleParams v = load_vehicle(dir.write("v.yaml", "mass_kg: 3\nIzz_kg_m2: 0.06\n"));
  EXPECT_EQ(v.mass_kg, 3.0);
  EXPECT_EQ(v.Izz_kg_m2, 0.06);
  const control::ControllerConfig c =
      load_controller(dir.write("c.yaml", "lqr: {roll: {r: 20}}\nyaw_des: 0.5\n"), v, hosts::test_resolvers());
  EXPECT_EQ(paper_params(c).roll.r, 20.0);
  EXPECT_EQ(c.node.setpoint.yaw_des_rad, 0.5);
  EXPECT_EQ(c.vehicle.mass_kg, 3.0);
  EXPECT_EQ(controllers::paper_controller(c)->vehicle().mass_kg, 3.0);

  const std::string bad_vehicle = dir.write("bad_v.yaml", "mass_kg: 0\n");
  const std::string vehicle_error = error_message<ConfigError>([&] { load_vehicle(bad_vehicle); });
  EXPECT_THAT(vehicle_error, HasSubstr(bad_vehicle + ": mass_kg: "));
  EXPECT_THAT(vehicle_error, HasSubstr("'0'"));
  const std::string bad_controller = dir.write("bad_c.yaml", "lqr:\n  roll: {r: -1}\n");
  const std::string controller_error =
      error_message<ConfigError>([&] { load_controller(bad_controller, v, hosts::test_resolvers()); });
  EXPECT_THAT(controller_error, HasSubstr(bad_controller + ": lqr.roll.r: "));
  EXPECT_THAT(controller_error, HasSubstr("-1"));
}

// ---------------------------------------------------------------------------------------------
// trajectory.csv

std::vector<std::string> split(const std::string& line, char sep = ',') {
  std::vector<std::string> out;
  std::string cell;
  std::stringstream ss(line);
  while (std::getline(ss, cell, sep)) out.push_back(cell);
  if (!line.empty() && line.back() == sep) out.emplace_back();
  return out;
}

std::vector<std::string> lines_of(const std::string& text) {
  std::vector<std::string> out;
  std::stringstream ss(text);
  for (std::string l; std::getline(ss, l);) out.push_back(l);
  return out;
}

std::uint64_t bits(double d) {
  std::uint64_t b;
  std::memcpy(&b, &d, sizeof b);
  return b;
}

/// Parses a whole cell with strtod; fails the test when the cell is not entirely a number.
double parse_cell(const std::string& cell) {
  char* end = nullptr;
  const double v = std::strtod(cell.c_str(), &end);
  EXPECT_TRUE(!cell.empty() && *end == '\0') << "not a number: '" << cell << "'";
  return v;
}

TEST(TrajectoryWriterTest, HeaderHasTheDocumentedColumns) {
  const std::vector<std::string> required = {
      "t", "x", "y", "z",  "vx", "vy", "vz", "qw",    "qx",    "qy",    "qz",       "roll",      "pitch",  "yaw",
      "p", "q", "r", "w1", "w2", "w3", "w4", "x_des", "y_des", "z_des", "roll_des", "pitch_des", "yaw_des"};
  // Appended after watchdog, so that readers by position of the older columns still work.
  const std::vector<std::string> tail = {"watchdog", "sat1", "sat2", "sat3", "sat4", "tilt_sat", "att_err"};
  TempDir dir;
  const std::string path = dir.file("trajectory.csv");
  {
    TrajectoryWriter w(path);
    w.close();
  }
  const auto lines = lines_of(read_text(path));
  ASSERT_EQ(lines.size(), 1u);
  const auto header = split(lines[0]);
  EXPECT_EQ(header, TrajectoryWriter::columns());
  for (const auto& c : required) {
    EXPECT_EQ(std::count(header.begin(), header.end(), c), 1) << c;
  }
  EXPECT_EQ(header.front(), "t");
  ASSERT_GE(header.size(), tail.size());
  EXPECT_EQ(std::vector<std::string>(header.end() - static_cast<std::ptrdiff_t>(tail.size()), header.end()), tail);
}

TEST(TrajectoryWriterTest, NumbersRoundTripExactly) {
  const std::vector<double> awkward = {0.1,
                                       1.0 / 3.0,
                                       -2.0 / 7.0,
                                       3.141592653589793,
                                       1e-300,
                                       std::numeric_limits<double>::denorm_min(),
                                       std::numeric_limits<double>::max(),
                                       -std::numeric_limits<double>::min(),
                                       -0.0,
                                       0.0,
                                       4830.6078372347,
                                       std::nextafter(1.0, 2.0),
                                       123456789.0123456789,
                                       -9.81e-17};
  TempDir dir;
  const std::string path = dir.file("trajectory.csv");
  std::vector<std::vector<double>> expected;
  {
    TrajectoryWriter w(path);
    for (std::size_t k = 0; k < 40; ++k) {
      auto a = [&](std::size_t i) { return awkward[(k + i) % awkward.size()]; };
      model::State x;
      x.p_W = {a(0), a(1), a(2)};
      x.v_W = {a(3), a(4), a(5)};
      x.q_WB = Eigen::Quaterniond(0.5 + 1e-3 * k, std::sqrt(0.2) / (k + 1), -1.0 / 3.0, 0.1 * k).normalized();
      x.w_B = {a(6), a(7), a(8)};
      x.omega_rad_s = model::Vector4(a(9), a(10), a(11), a(12));
      const Eigen::Vector4d cmd(a(13), a(0) * 3.0, a(5) / 7.0, 1e10 / 3.0);
      ControlColumns c{a(1),
                       a(2),
                       a(3),
                       a(4),
                       a(5),
                       a(6),
                       Eigen::Vector4d(a(7), a(8), a(9), a(10)),
                       k % 2 == 1,
                       {k % 4 == 0, k % 4 == 1, k % 5 == 2, k % 7 == 3},
                       k % 3 == 1,
                       a(11) / 3.0,
                       {},   // output_names: none
                       {}};  // outputs
      const double t = static_cast<double>(k) * 1e7 / 1e9;
      const bool watchdog = k % 3 == 0;
      w.write(t, x, cmd, c, watchdog);
      const model::Euler e = model::euler_from_quaternion(x.q_WB);
      expected.push_back({t,
                          x.p_W.x(),
                          x.p_W.y(),
                          x.p_W.z(),
                          x.v_W.x(),
                          x.v_W.y(),
                          x.v_W.z(),
                          x.q_WB.w(),
                          x.q_WB.x(),
                          x.q_WB.y(),
                          x.q_WB.z(),
                          e.roll_rad,
                          e.pitch_rad,
                          e.yaw_rad,
                          x.w_B.x(),
                          x.w_B.y(),
                          x.w_B.z(),
                          x.omega_rad_s[0],
                          x.omega_rad_s[1],
                          x.omega_rad_s[2],
                          x.omega_rad_s[3],
                          cmd[0],
                          cmd[1],
                          cmd[2],
                          cmd[3],
                          c.x_des,
                          c.y_des,
                          c.z_des,
                          c.roll_des,
                          c.pitch_des,
                          c.yaw_des,
                          c.U[0],
                          c.U[1],
                          c.U[2],
                          c.U[3],
                          c.safety ? 1.0 : 0.0,
                          watchdog ? 1.0 : 0.0,
                          c.rotor_saturated[0] ? 1.0 : 0.0,
                          c.rotor_saturated[1] ? 1.0 : 0.0,
                          c.rotor_saturated[2] ? 1.0 : 0.0,
                          c.rotor_saturated[3] ? 1.0 : 0.0,
                          c.tilt_saturated ? 1.0 : 0.0,
                          c.attitude_error});
    }
    w.close();
  }
  const auto lines = lines_of(read_text(path));
  ASSERT_EQ(lines.size(), expected.size() + 1);
  const auto& columns = TrajectoryWriter::columns();
  ASSERT_EQ(columns.size(), expected[0].size());
  for (std::size_t k = 0; k < expected.size(); ++k) {
    const auto cells = split(lines[k + 1]);
    ASSERT_EQ(cells.size(), columns.size()) << "row " << k;
    for (std::size_t i = 0; i < cells.size(); ++i) {
      const double v = parse_cell(cells[i]);
      EXPECT_EQ(bits(v), bits(expected[k][i]))
          << "row " << k << " column " << columns[i] << ": wrote " << expected[k][i] << " as '" << cells[i] << "'";
    }
  }
}

TEST(SeriesRecorderTest, HoldsWhatReadSeriesReadsFromTheWrittenCsvBitForBit) {
  // The in-memory series (sweeps) and the CSV read back (run) must judge the same numbers: every
  // column, saturation flags and U1 included, and NaN setpoints (open loop) alike.
  const std::vector<double> awkward = {
      0.1,      1.0 / 3.0, -2.0 / 7.0, 1e-300, -0.0, 4830.6078372347, std::nextafter(1.0, 2.0), 19.227600000000003,
      -9.81e-17};
  TempDir dir;
  const std::string path = dir.file("trajectory.csv");
  SeriesRecorder recorder;
  {
    TrajectoryWriter w(path);
    for (std::size_t k = 0; k < 30; ++k) {
      auto a = [&](std::size_t i) { return awkward[(k + i) % awkward.size()]; };
      model::State x;
      x.p_W = {a(0), a(1), a(2)};
      x.q_WB = Eigen::Quaterniond(0.5 + 1e-3 * k, std::sqrt(0.2) / (k + 1), -1.0 / 3.0, 0.1 * k).normalized();
      ControlColumns c = k % 6 == 5 ? ControlColumns::none()
                                    : ControlColumns{a(1),
                                                     a(2),
                                                     a(3),
                                                     a(4),
                                                     a(5),
                                                     a(6),
                                                     Eigen::Vector4d(a(7), a(8), 0.0, 0.0),
                                                     false,
                                                     {k % 4 == 0, k % 4 == 1, k % 5 == 2, k % 7 == 3},
                                                     k % 3 == 1,
                                                     std::numeric_limits<double>::quiet_NaN(),  // no R_d
                                                     {},                                        // output_names
                                                     {}};                                       // outputs
      const double t = static_cast<double>(k) * 1e7 / 1e9;
      const Eigen::Vector4d command(a(2), a(3), 0.0, -a(4));
      w.write(t, x, command, c, k % 5 == 1);
      recorder.add(t, x, command, c, k % 5 == 1);
    }
    w.close();
  }
  const Series from_csv = read_series(path);
  const Series& in_memory = recorder.series();
  std::vector<std::string> names;
  for (const auto& [name, v] : from_csv.values) names.push_back(name);
  // The CSV has every column a series of a four-rotor vehicle holds.
  std::vector<std::string> want(series_columns().begin(), series_columns().begin() + kSeriesColumnsOfFourRotors);
  std::sort(want.begin(), want.end());
  EXPECT_EQ(names, want);
  ASSERT_EQ(in_memory.values.size(), from_csv.values.size());
  ASSERT_EQ(in_memory.t_s.size(), 30u);
  for (std::size_t k = 0; k < 30; ++k) EXPECT_EQ(bits(in_memory.t_s[k]), bits(from_csv.t_s[k])) << k;
  for (const auto& [name, column] : from_csv.values) {
    ASSERT_TRUE(in_memory.values.count(name)) << name;
    const auto& mine = in_memory.values.at(name);
    ASSERT_EQ(mine.size(), column.size()) << name;
    for (std::size_t k = 0; k < column.size(); ++k) {
      EXPECT_TRUE(bits(mine[k]) == bits(column[k]) || (std::isnan(mine[k]) && std::isnan(column[k])))
          << name << " row " << k << ": " << mine[k] << " vs " << column[k];
    }
  }
  // Rows with a flag set: k % 4 == 1 sets sat2 (k = 1, 5, ..., 29 less the open-loop rows 5, 17, 29).
  EXPECT_EQ(std::count(in_memory.values.at("sat2").begin(), in_memory.values.at("sat2").end(), 1.0), 5);
  Scenario sc;
  EXPECT_EQ(evaluate_saturation(sc, in_memory)->figures, evaluate_saturation(sc, from_csv)->figures);
}

TEST(TrajectoryWriterTest, OpenLoopColumnsAreNan) {
  TempDir dir;
  const std::string path = dir.file("trajectory.csv");
  {
    TrajectoryWriter w(path);
    w.write(0.0, model::State{}, Eigen::Vector4d::Zero(), ControlColumns::none());
    w.close();
  }
  const auto lines = lines_of(read_text(path));
  ASSERT_EQ(lines.size(), 2u);
  const auto header = split(lines[0]);
  const auto cells = split(lines[1]);
  ASSERT_EQ(cells.size(), header.size());
  for (std::size_t i = 0; i < cells.size(); ++i) {
    const double v = parse_cell(cells[i]);
    const bool control = header[i].ends_with("_des") || header[i].starts_with("U") || header[i] == "att_err";
    if (control) {
      EXPECT_TRUE(std::isnan(v)) << header[i];
    } else {
      EXPECT_TRUE(std::isfinite(v)) << header[i];
    }
  }
}

TEST(TrajectoryWriterTest, DestructorFlushesWithoutClose) {
  TempDir dir;
  const std::string path = dir.file("trajectory.csv");
  {
    TrajectoryWriter w(path);
    for (int k = 0; k < 3000; ++k) w.write(k * 0.01, model::State{}, Eigen::Vector4d::Zero(), ControlColumns::none());
  }
  EXPECT_EQ(lines_of(read_text(path)).size(), 3001u);
}

TEST(TrajectoryWriterTest, UnwritablePathThrowsNamingIt) {
  TempDir dir;
  const std::string path = dir.file("no/such/dir/trajectory.csv");
  EXPECT_THAT(error_message<std::runtime_error>([&] { TrajectoryWriter w(path); }), HasSubstr(path));
}

// ---------------------------------------------------------------------------------------------
// Command schedules (openloop input)

TEST(CommandScheduleTest, ReadsAGoodFile) {
  TempDir dir;
  const std::string path = dir.write("cmd.csv",
                                     "t,w1,w2,w3,w4\r\n"
                                     "0,4830.5,4830.5,4830.5,4830.5\r\n"
                                     "\r\n"
                                     " 0.5 , 0, 1e3, 2.25 ,3\n"
                                     "1.25,10,20,30,40\n");
  const auto rows = read_command_schedule(path);
  ASSERT_EQ(rows.size(), 3u);
  EXPECT_EQ(rows[0].t_s, 0.0);
  EXPECT_EQ(rows[0].omega_rad_s, Eigen::Vector4d::Constant(4830.5));
  EXPECT_EQ(rows[1].t_s, 0.5);
  EXPECT_EQ(rows[1].omega_rad_s, Eigen::Vector4d(0.0, 1000.0, 2.25, 3.0));
  EXPECT_EQ(rows[2].t_s, 1.25);
  EXPECT_EQ(rows[2].omega_rad_s, Eigen::Vector4d(10.0, 20.0, 30.0, 40.0));
}

struct BadSchedule {
  std::string label;
  std::string text;
  int line;
  std::string must_mention;
};

class BadScheduleTest : public ::testing::TestWithParam<BadSchedule> {};

TEST_P(BadScheduleTest, RejectedWithFileAndLine) {
  const BadSchedule& b = GetParam();
  TempDir dir;
  const std::string path = dir.write(b.label + ".csv", b.text);
  const std::string msg = error_message<std::runtime_error>([&] { read_command_schedule(path); });
  EXPECT_THAT(msg, StartsWith(path + ":" + std::to_string(b.line) + ": ")) << "for\n" << b.text;
  EXPECT_THAT(msg, HasSubstr(b.must_mention));
}

INSTANTIATE_TEST_SUITE_P(
    Csv, BadScheduleTest,
    ::testing::Values(BadSchedule{"bad_header", "time,w1,w2,w3,w4\n0,1,1,1,1\n", 1, "header"},
                      BadSchedule{"header_missing_column", "t,w1,w2,w3\n0,1,1,1\n", 1, "t,w1,w2,w3,w4"},
                      BadSchedule{"empty_file", "", 1, "empty"},
                      BadSchedule{"no_rows", "t,w1,w2,w3,w4\n", 1, "no command rows"},
                      BadSchedule{"not_a_number", "t,w1,w2,w3,w4\n0,1,1,1,1\n1,1,fast,1,1\n", 3, "'fast'"},
                      BadSchedule{"number_with_junk", "t,w1,w2,w3,w4\n0,1,1,1,1x\n", 2, "'1x'"},
                      BadSchedule{"empty_cell", "t,w1,w2,w3,w4\n0,1,,1,1\n", 2, "not a number"},
                      BadSchedule{"equal_times", "t,w1,w2,w3,w4\n0,1,1,1,1\n0.5,1,1,1,1\n0.5,2,2,2,2\n", 4, "increase"},
                      BadSchedule{"decreasing_times", "t,w1,w2,w3,w4\n0,1,1,1,1\n1,1,1,1,1\n\n0.5,2,2,2,2\n", 5,
                                  "increase"},
                      BadSchedule{"negative_time", "t,w1,w2,w3,w4\n-1,1,1,1,1\n", 2, "time"},
                      BadSchedule{"negative_speed", "t,w1,w2,w3,w4\n0,1,1,1,1\n1,1,1,-5,1\n", 3, "w3"},
                      BadSchedule{"infinite_speed", "t,w1,w2,w3,w4\n0,1,inf,1,1\n", 2, "finite"},
                      BadSchedule{"nan_time", "t,w1,w2,w3,w4\nnan,1,1,1,1\n", 2, "finite"},
                      BadSchedule{"too_few_columns", "t,w1,w2,w3,w4\n0,1,1,1,1\n1,1,1,1\n", 3, "got 4"},
                      BadSchedule{"too_many_columns", "t,w1,w2,w3,w4\n0,1,1,1,1,1\n", 2, "got 6"},
                      BadSchedule{"trailing_comma_row", "t,w1,w2,w3,w4\n0,1,1,1,1,\n", 2, "trailing comma"},
                      BadSchedule{"trailing_comma_header", "t,w1,w2,w3,w4,\n0,1,1,1,1\n", 1, "trailing comma"}),
    [](const auto& info) { return info.param.label; });

TEST(CommandScheduleTest, MissingFileNamesIt) {
  TempDir dir;
  const std::string path = dir.file("none.csv");
  EXPECT_THAT(error_message<std::runtime_error>([&] { read_command_schedule(path); }), HasSubstr(path));
}

// ---------------------------------------------------------------------------------------------
// Step report

/// 10 s at 100 Hz of channel z: at 0 until t_step, then a first-order rise (time constant T) to
/// `final`, with the setpoint z_des stepping from 0 to 10 at t_step. Also a flat "roll" channel.
Series first_order_series(double t_step, double T, double final_value) {
  Series s;
  for (int k = 0; k <= 1000; ++k) {
    const double t = k / 100.0;
    s.t_s.push_back(t);
    s.append("z", t < t_step ? 0.0 : final_value * (1.0 - std::exp(-(t - t_step) / T)));
    s.append("z_des", t < t_step ? 0.0 : 10.0);
    s.append("roll", 0.0);
    s.append("roll_des", 0.0);
  }
  return s;
}

StepSpec z_step(double at, std::vector<Criterion> criteria) {
  return StepSpec{
      .channel = "z", .t_step_s = at, .criteria = std::move(criteria), .reference_source = {}, .reference = {}};
}

TEST(StepReportTest, CriteriaPassAndFail) {
  // T = 0.5 s: t95 = 0.5 ln 20 = 1.498 -> 1.5 s on the grid; no overshoot; no peak time.
  const Series series = first_order_series(1.0, 0.5, 10.0);
  const auto none = std::nullopt;
  const std::vector<StepSpec> steps = {
      z_step(1.0, {{"t95_s", 1.4, 1.6}, {"overshoot_pct", none, 1.0}, {"overshoot_pct", 0.0, 0.0}}),
      z_step(1.0, {{"t95_s", 1.6, none}}),         // too fast for a lower bound
      z_step(1.0, {{"t95_s", none, 1.4}}),         // too slow for an upper bound
      z_step(1.0, {{"peak_time_s", none, none}}),  // no value: fails even unbounded
      z_step(1.0, {}),                             // nothing to check: passes
      z_step(1.0, {{"t95_s", 1.5, 1.5}}),          // bounds are inclusive
  };
  const auto results = evaluate_steps(steps, series);
  ASSERT_EQ(results.size(), steps.size());

  const StepResult& r0 = results[0];
  EXPECT_EQ(r0.figures.initial, 0.0);
  EXPECT_EQ(r0.figures.target, 10.0);  // the setpoint at the step time
  ASSERT_TRUE(r0.figures.t95_s.has_value());
  EXPECT_NEAR(*r0.figures.t95_s, 1.5, 1e-12);
  ASSERT_EQ(r0.criteria.size(), 3u);
  for (const auto& c : r0.criteria) EXPECT_TRUE(c.passed) << c.criterion.figure;
  EXPECT_EQ(r0.criteria[0].value, r0.figures.t95_s);
  EXPECT_TRUE(r0.passed);

  EXPECT_FALSE(results[1].passed);
  EXPECT_FALSE(results[1].criteria[0].passed);
  EXPECT_FALSE(results[2].passed);
  EXPECT_FALSE(results[3].passed);
  EXPECT_FALSE(results[3].criteria[0].value.has_value());
  EXPECT_TRUE(results[4].passed);
  EXPECT_TRUE(results[4].criteria.empty());
  ASSERT_TRUE(results[5].figures.t95_s.has_value());
  EXPECT_EQ(*results[5].figures.t95_s, 1.5);  // t[250] - 1.0, exact
  EXPECT_TRUE(results[5].passed);

  EXPECT_FALSE(all_passed(results));
  EXPECT_TRUE(all_passed({results[0], results[4]}));
  EXPECT_TRUE(all_passed({}));
}

// ---------------------------------------------------------------------------------------------
// Criteria sets: spec and paper, and what --judge judges

TEST(JudgeTest, NamesParseAndJudgeOneSetEach) {
  EXPECT_EQ(judge_names(), (std::vector<std::string>{"spec", "paper", "none"}));
  for (const std::string& name : judge_names()) EXPECT_EQ(to_string(*parse_judge(name)), name);
  EXPECT_FALSE(parse_judge("Spec").has_value());
  EXPECT_FALSE(parse_judge("").has_value());
  EXPECT_TRUE(judges(Judge::kSpec, CriteriaSet::kSpec));
  EXPECT_FALSE(judges(Judge::kSpec, CriteriaSet::kPaper));
  EXPECT_TRUE(judges(Judge::kPaper, CriteriaSet::kPaper));
  EXPECT_FALSE(judges(Judge::kNone, CriteriaSet::kSpec));
  EXPECT_FALSE(judges(Judge::kNone, CriteriaSet::kPaper));
}

TEST(JudgeTest, SpecPaperAndTheOldCriteriaKeyAreRead) {
  TempDir dir;
  const std::string path = dir.write("sets.yaml",
                                     "analysis:\n"
                                     "  steps:\n"
                                     "    - channel: z\n"
                                     "      paper: {overshoot_pct: [15, 21]}\n"
                                     "      spec: {overshoot_pct: [null, 25], t95_s: [null, 5]}\n"
                                     "    - channel: z\n"
                                     "      at_s: 1\n"
                                     "      criteria: {t95_s: [null, 3]}\n"
                                     "  hold:\n"
                                     "    paper: {max_vertical_error_m: [0.1, 0.3]}\n"
                                     "  limits:\n"
                                     "    spec: {max_saturated_s: 0.5}\n"
                                     "    paper: {max_tilt_saturated_s: 0}\n");
  const Scenario sc = load_scenario(path, hosts::test_resolvers());
  ASSERT_EQ(sc.steps.size(), 2u);
  const auto& c = sc.steps[0].criteria;  // spec first, then paper, each in file order
  ASSERT_EQ(c.size(), 3u);
  EXPECT_EQ(c[0].figure, "overshoot_pct");
  EXPECT_EQ(c[0].set, CriteriaSet::kSpec);
  EXPECT_FALSE(c[0].min.has_value());
  EXPECT_EQ(c[0].max, 25.0);
  EXPECT_EQ(c[1].figure, "t95_s");
  EXPECT_EQ(c[1].set, CriteriaSet::kSpec);
  EXPECT_EQ(c[2].set, CriteriaSet::kPaper);
  EXPECT_EQ(c[2].min, 15.0);
  EXPECT_EQ(c[2].max, 21.0);
  ASSERT_EQ(sc.steps[1].criteria.size(), 1u);  // the old key: a spec
  EXPECT_EQ(sc.steps[1].criteria[0].set, CriteriaSet::kSpec);
  EXPECT_EQ(sc.steps[1].criteria[0].max, 3.0);
  ASSERT_TRUE(sc.hold.has_value());
  ASSERT_EQ(sc.hold->criteria.size(), 1u);
  EXPECT_EQ(sc.hold->criteria[0].set, CriteriaSet::kPaper);
  ASSERT_TRUE(sc.limits.has_value());
  ASSERT_EQ(sc.limits->criteria.size(), 2u);
  EXPECT_EQ(sc.limits->criteria[0].figure, "saturated_s");
  EXPECT_EQ(sc.limits->criteria[0].set, CriteriaSet::kSpec);
  EXPECT_EQ(sc.limits->criteria[1].figure, "tilt_saturated_s");
  EXPECT_EQ(sc.limits->criteria[1].set, CriteriaSet::kPaper);
  EXPECT_TRUE(has_criteria(sc, CriteriaSet::kSpec));
  EXPECT_TRUE(has_criteria(sc, CriteriaSet::kPaper));
}

TEST(JudgeTest, OnlyTheJudgedSetDecidesTheVerdict) {
  // T = 0.5 s: t95 = 0.5 ln 20 = 1.498 -> 1.5 s on the grid, no overshoot. The spec asks for 95 %
  // within 2 s (met); the paper band, of a slower controller, for 3-4 s (left by this faster one).
  const Series series = first_order_series(1.0, 0.5, 10.0);
  const auto none = std::nullopt;
  const std::vector<StepSpec> steps = {z_step(1.0, {{"t95_s", none, 2.0, CriteriaSet::kSpec},
                                                    {"t95_s", 3.0, 4.0, CriteriaSet::kPaper},
                                                    {"overshoot_pct", none, 2.0, CriteriaSet::kPaper}})};
  Scenario sc;
  sc.name = "judge";
  sc.steps = steps;

  const auto spec = evaluate_steps(steps, series, Judge::kSpec);
  EXPECT_TRUE(spec[0].passed);
  EXPECT_TRUE(spec[0].criteria[0].judged && spec[0].criteria[0].passed);
  EXPECT_FALSE(spec[0].criteria[1].judged);
  EXPECT_FALSE(spec[0].criteria[1].passed);  // checked all the same: 1.5 s is outside [3, 4]
  EXPECT_TRUE(spec[0].criteria[2].passed);
  EXPECT_EQ(judged_criteria(spec, {}, {}, {}), 1u);

  const auto paper = evaluate_steps(steps, series, Judge::kPaper);
  EXPECT_FALSE(paper[0].passed);
  EXPECT_FALSE(paper[0].criteria[0].judged);
  EXPECT_TRUE(paper[0].criteria[1].judged);
  EXPECT_FALSE(paper[0].criteria[1].passed);
  EXPECT_EQ(judged_criteria(paper, {}, {}, {}), 2u);

  const auto figures_only = evaluate_steps(steps, series, Judge::kNone);
  EXPECT_TRUE(figures_only[0].passed);  // nothing judged, nothing failed
  EXPECT_EQ(judged_criteria(figures_only, {}, {}, {}), 0u);
  EXPECT_EQ(figures_only[0].figures.t95_s, spec[0].figures.t95_s);

  const nlohmann::json js = metrics_json(sc, spec, {}, {}, {}, Judge::kSpec);
  const nlohmann::json jp = metrics_json(sc, paper, {}, {}, {}, Judge::kPaper);
  const nlohmann::json jn = metrics_json(sc, figures_only, {}, {}, {}, Judge::kNone);
  EXPECT_EQ(js.at("judged"), "spec");
  EXPECT_EQ(js.at("passed"), true);
  EXPECT_EQ(jp.at("judged"), "paper");
  EXPECT_EQ(jp.at("passed"), false);
  EXPECT_EQ(jp.at("steps")[0].at("passed"), false);
  EXPECT_EQ(jp.at("judged_criteria"), 2);
  EXPECT_EQ(jn.at("judged"), "none");
  EXPECT_TRUE(jn.at("passed").is_null());
  EXPECT_TRUE(jn.at("steps")[0].at("passed").is_null());
  const auto& c1 = jp.at("steps")[0].at("criteria")[1];
  EXPECT_EQ(c1.at("set"), "paper");
  EXPECT_EQ(c1.at("min"), 3.0);
  EXPECT_EQ(c1.at("max"), 4.0);
  EXPECT_DOUBLE_EQ(c1.at("value").get<double>(), 1.5);
  EXPECT_EQ(c1.at("passed"), false);
  EXPECT_EQ(c1.at("judged"), true);
  EXPECT_EQ(js.at("steps")[0].at("criteria")[1].at("judged"), false);
  EXPECT_FALSE(js.contains("judged_note"));

  // metrics.txt: the set judged, and per figure both bands, ok/FAIL for the judged one, in/out for the other.
  const std::string table = format_step_table(sc, paper, {}, {}, {}, Judge::kPaper);
  EXPECT_NE(table.find("judged against: paper (the paper's controller's measured response bands)"), std::string::npos)
      << table;
  EXPECT_NE(table.find("FAIL ("), std::string::npos) << table;  // the step's verdict
  const auto row = table.find("  t95_s ");
  ASSERT_NE(row, std::string::npos) << table;
  const std::string line = table.substr(row, table.find('\n', row) - row);
  EXPECT_NE(line.find("[-, 2] in"), std::string::npos) << line;
  EXPECT_NE(line.find("[3, 4] FAIL"), std::string::npos) << line;
  const std::string spec_table = format_step_table(sc, spec, {}, {}, {}, Judge::kSpec);
  EXPECT_NE(spec_table.find("[-, 2] ok"), std::string::npos) << spec_table;
  EXPECT_NE(spec_table.find("[3, 4] out"), std::string::npos) << spec_table;
  EXPECT_NE(format_step_table(sc, figures_only, {}, {}, {}, Judge::kNone).find("figures only"), std::string::npos);
}

TEST(JudgeTest, AScenarioWithoutTheJudgedSetSaysNothingIsJudged) {
  Scenario sc;
  sc.steps = {z_step(1.0, {{"t95_s", std::nullopt, 2.0, CriteriaSet::kSpec}})};
  EXPECT_EQ(nothing_judged_note(sc, Judge::kSpec), "");
  EXPECT_EQ(nothing_judged_note(sc, Judge::kPaper), "no paper bands in this scenario: nothing judged");
  EXPECT_EQ(nothing_judged_note(sc, Judge::kNone), "");
  sc.steps[0].criteria[0].set = CriteriaSet::kPaper;
  EXPECT_EQ(nothing_judged_note(sc, Judge::kSpec), "no spec criteria in this scenario: nothing judged");
  const auto results = evaluate_steps(sc.steps, first_order_series(1.0, 0.5, 10.0), Judge::kSpec);
  const nlohmann::json j = metrics_json(sc, results, {}, {}, {}, Judge::kSpec);
  EXPECT_EQ(j.at("passed"), true);
  EXPECT_EQ(j.at("judged_criteria"), 0);
  EXPECT_EQ(j.at("judged_note"), "no spec criteria in this scenario: nothing judged");
  const std::string table = format_step_table(sc, results, {}, {}, {}, Judge::kSpec);
  EXPECT_NE(table.find("no spec criteria ("), std::string::npos) << table;  // the step's verdict
}

TEST(JudgeTest, HoldAndLimitsJudgeTheirSetOnly) {
  // z holds 0.25 m below its setpoint: max_vertical_error_m = 0.25 (0.25 is exact in binary).
  Series s;
  for (int k = 0; k <= 200; ++k) {
    s.t_s.push_back(k / 100.0);
    for (const char* c : {"x", "y", "x_des", "y_des"}) s.append(c, 0.0);
    s.append("z", 4.75);
    s.append("z_des", 5.0);
  }
  const HoldSpec hold{0.0,
                      {{"max_vertical_error_m", std::nullopt, 0.5, CriteriaSet::kSpec},
                       {"max_vertical_error_m", std::nullopt, 0.1, CriteriaSet::kPaper}}};
  const HoldResult spec = evaluate_hold(hold, s, Judge::kSpec);
  EXPECT_DOUBLE_EQ(spec.figures.at("max_vertical_error_m"), 0.25);
  EXPECT_TRUE(spec.passed);
  EXPECT_FALSE(spec.criteria[1].passed);
  EXPECT_FALSE(spec.criteria[1].judged);
  EXPECT_FALSE(evaluate_hold(hold, s, Judge::kPaper).passed);
  EXPECT_TRUE(evaluate_hold(hold, s, Judge::kNone).passed);
}

TEST(StepReportTest, SteadyStateErrorCriterion) {
  const Series short_of_target = first_order_series(0.0, 0.3, 9.5);  // 5 % short
  const auto results = evaluate_steps({z_step(0.0, {{"steady_state_error_pct", std::nullopt, 1.0}}),
                                       z_step(0.0, {{"steady_state_error_pct", 4.9, 5.1}})},
                                      short_of_target);
  ASSERT_TRUE(results[0].figures.steady_state_error_pct.has_value());
  EXPECT_NEAR(*results[0].figures.steady_state_error_pct, 5.0, 1e-6);
  EXPECT_FALSE(results[0].passed);
  // 5 % short is outside the 2 % band: the run ended before settling, so even a band around the
  // measured error fails, and says why.
  EXPECT_FALSE(results[1].passed);
  EXPECT_NE(results[1].criteria[0].note.find("ended before settling"), std::string::npos);

  // 1 % short settles (inside the 2 % band): the error is judged on its value.
  const Series close = first_order_series(0.0, 0.3, 9.9);
  const auto near = evaluate_steps({z_step(0.0, {{"steady_state_error_pct", 0.9, 1.1}})}, close);
  EXPECT_EQ(near[0].figures.verdict, analysis::StepVerdict::kSettled);
  EXPECT_TRUE(near[0].passed);
  EXPECT_EQ(near[0].criteria[0].note, "");
}

// The altitude step that reported "settled at 1.600 s": 0 -> 2 m, stopped 1.65 s after the step
// while still climbing.
Series climbing_series() {
  Series s;
  for (int k = 0; k <= 165; ++k) {
    const double t = k / 100.0;
    s.t_s.push_back(t);
    s.append("z", 2.0 * (1.0 - std::exp(-t / 1.4)));
    s.append("z_des", 2.0);
  }
  return s;
}

TEST(StepReportTest, ASettlingCriterionFailsWhenTheRunEndsBeforeSettling) {
  const auto results = evaluate_steps(
      {z_step(0.0, {{"settling_time_2pct_s", std::nullopt, 2.0}, {"t95_s", std::nullopt, 5.0}})}, climbing_series());
  const StepResult& r = results[0];
  EXPECT_EQ(r.figures.verdict, analysis::StepVerdict::kNotSettled);
  EXPECT_FALSE(r.passed);
  EXPECT_FALSE(r.criteria[0].value.has_value());
  EXPECT_NE(r.criteria[0].note.find("ended before settling"), std::string::npos) << r.criteria[0].note;
  EXPECT_FALSE(r.criteria[1].passed);  // 95 % never reached: no value
  EXPECT_EQ(r.criteria[1].note, "");

  Scenario sc;
  sc.name = "climb";
  const std::string table = format_step_table(sc, results);
  EXPECT_NE(table.find("not settled"), std::string::npos) << table;
  EXPECT_NE(table.find("the run ended before settling"), std::string::npos) << table;
  EXPECT_EQ(table.find("1.600"), std::string::npos) << table;
  TempDir dir;
  write_metrics_json(dir.file("metrics.json"), sc, results);
  const auto j = nlohmann::json::parse(read_text(dir.file("metrics.json")));
  const auto& step = j.at("steps")[0];
  EXPECT_EQ(step.at("verdict"), "not settled");
  EXPECT_EQ(step.at("final_window_s"), 1.0);
  EXPECT_TRUE(step.at("figures").at("settling_time_2pct_s").is_null());
  EXPECT_NE(step.at("criteria")[0].at("note").get<std::string>().find("ended before settling"), std::string::npos);
  EXPECT_TRUE(step.at("criteria")[1].at("note").is_null());
  EXPECT_EQ(j.at("passed"), false);
}

TEST(StepReportTest, AStepIsJudgedUpToTheNextStepOfItsChannel) {
  // z: 0 -> 1 at 1 s, back to 0 at 6 s (first order, T = 0.2 s), end at 12 s; roll steps at 3 s.
  Series s;
  const double T = 0.2;
  double at6 = 0.0;
  for (int k = 0; k <= 1200; ++k) {
    const double t = k / 100.0;
    s.t_s.push_back(t);
    double z = t < 1.0 ? 0.0 : 1.0 - std::exp(-(t - 1.0) / T);
    if (k == 600) at6 = z;
    if (t >= 6.0) z = at6 * std::exp(-(t - 6.0) / T);
    s.append("z", z);
    s.append("z_des", t < 1.0 ? 0.0 : (t < 6.0 ? 1.0 : 0.0));
    s.append("roll", 0.0);
    s.append("roll_des", 0.0);
  }
  StepSpec roll;
  roll.channel = "roll";
  roll.t_step_s = 3.0;
  const auto r = evaluate_steps(
      {z_step(1.0, {{"settling_time_2pct_s", 0.7, 0.9}}), roll, z_step(6.0, {{"settling_time_2pct_s", 0.7, 0.9}})}, s);
  ASSERT_EQ(r.size(), 3u);
  for (const StepResult* step : {&r[0], &r[2]}) {
    EXPECT_EQ(step->figures.verdict, analysis::StepVerdict::kSettled);
    ASSERT_TRUE(step->figures.settling_time_2pct_s.has_value());
    EXPECT_NEAR(*step->figures.settling_time_2pct_s, T * std::log(50.0), 0.01 + 1e-9);  // 0.782 s
    EXPECT_TRUE(step->passed);
  }
  EXPECT_DOUBLE_EQ(r[0].figures.post_step_s, 4.99);  // to the last sample before 6 s
  EXPECT_EQ(r[1].figures.verdict, analysis::StepVerdict::kZeroStep);
  EXPECT_NEAR(r[2].figures.step, -at6, 1e-15);
}

TEST(StepReportTest, YawIsJudgedOnTheShortestPath) {
  // 3.0 -> -3.0 rad: the vehicle turns +0.283 rad (first order, T = 0.3 s) and the angle wraps.
  Series s;
  const double size = 2.0 * std::numbers::pi - 6.0;
  for (int k = 0; k <= 800; ++k) {
    const double t = k / 100.0;
    s.t_s.push_back(t);
    const double yaw = t < 1.0 ? 3.0 : 3.0 + size * (1.0 - std::exp(-(t - 1.0) / 0.3));
    s.append("yaw", std::remainder(yaw, 2.0 * std::numbers::pi));
    s.append("yaw_des", t < 1.0 ? 3.0 : -3.0);
  }
  StepSpec yaw;
  yaw.channel = "yaw";
  yaw.t_step_s = 1.0;
  yaw.criteria = {{"rise_time_s", 0.5, 0.8}};  // 0.3 ln 9 = 0.659 s
  const auto r = evaluate_steps({yaw}, s);
  EXPECT_NEAR(r[0].figures.step, 0.2832, 1e-4);
  EXPECT_EQ(r[0].figures.target, -3.0);
  ASSERT_TRUE(r[0].figures.rise_time_s.has_value());
  EXPECT_NEAR(*r[0].figures.rise_time_s, 0.3 * std::log(9.0), 0.01 + 1e-9);
  EXPECT_TRUE(r[0].passed);
  Scenario sc;
  EXPECT_NE(format_step_table(sc, r).find("shortest path +0.283"), std::string::npos) << format_step_table(sc, r);
}

// --- Saturation ----------------------------------------------------------------------------------

Series saturation_series() {
  // 100 Hz, 301 rows; rotor 2 saturated on rows 50..179 (130 rows), rotor 4 on rows 60..189 (130),
  // the tilt limit on rows 10..19; U1 = m g + 1 N on every row.
  Series s;
  const model::VehicleParams v;
  for (int k = 0; k <= 300; ++k) {
    s.t_s.push_back(k / 100.0);
    s.append("sat1", 0.0);
    s.append("sat2", k >= 50 && k < 180 ? 1.0 : 0.0);
    s.append("sat3", 0.0);
    s.append("sat4", k >= 60 && k < 190 ? 1.0 : 0.0);
    s.append("tilt_sat", k >= 10 && k < 20 ? 1.0 : 0.0);
    s.append("U1", v.mass_kg * v.gravity_m_s2 + 1.0);
  }
  return s;
}

TEST(SaturationTest, TimesAreTicksTimesThePeriod) {
  Scenario sc;
  const auto r = evaluate_saturation(sc, saturation_series());
  ASSERT_TRUE(r.has_value());
  EXPECT_NEAR(r->rotor_saturated_s(1), 0.0, 1e-12);
  EXPECT_NEAR(r->rotor_saturated_s(2), 1.30, 1e-9);
  EXPECT_NEAR(r->rotor_saturated_s(3), 0.0, 1e-12);
  EXPECT_NEAR(r->rotor_saturated_s(4), 1.30, 1e-9);
  EXPECT_NEAR(r->saturated_s(), 1.40, 1e-9);  // rows 50..189: any rotor
  EXPECT_NEAR(r->tilt_saturated_s(), 0.10, 1e-9);
  EXPECT_NEAR(r->figures.at("rms_u1_deviation_n"), 1.0, 1e-9);
  EXPECT_TRUE(r->passed);  // no limits: nothing to fail
  const std::string w = saturation_warning(*r);
  EXPECT_NE(w.find("rotors 2, 4"), std::string::npos) << w;
  EXPECT_NE(w.find("1.400 s"), std::string::npos) << w;
  EXPECT_NE(w.find("tilt limit acted for 0.100 s"), std::string::npos) << w;
  EXPECT_EQ(
      saturation_warning(*evaluate_saturation(
          sc, Series{{0.0, 0.01},
                     {{"sat1", {0, 0}}, {"sat2", {0, 0}}, {"sat3", {0, 0}}, {"sat4", {0, 0}}, {"tilt_sat", {0, 0}}}})),
      "");
}

// Motors off on the ground (a disarmed flight stack before take-off and after landing) is no
// saturation: rows with every command at omega_min, z = 0 and vz = 0 are not counted; the same
// commands in the air (z > 0) or while the vehicle moves are.
TEST(SaturationTest, MotorsOffOnTheGroundAreNoSaturation) {
  Scenario sc;
  Series s;
  // 100 Hz, 401 rows: on the ground with the motors off (rows 0..99), flying (100..299: every rotor at
  // omega_max on rows 150..159), falling with the motors off (300..349, z > 0), resting with the
  // motors off again (350..400).
  for (int k = 0; k <= 400; ++k) {
    const bool off = k < 100 || k >= 300;
    const bool max = k >= 150 && k < 160;
    const double w = off ? 0.0 : max ? sc.vehicle.motor.omega_max_rad_s : 5000.0;
    s.t_s.push_back(k / 100.0);
    for (int r = 1; r <= 4; ++r) {
      s.append("sat" + std::to_string(r), off || max ? 1.0 : 0.0);
      s.append("cmd" + std::to_string(r), w);
    }
    s.append("tilt_sat", 0.0);
    s.append("z", k < 100 || k >= 350 ? 0.0 : 1.0);
    s.append("vz", k < 100 || k >= 350 ? 0.0 : -0.5);
    s.append("U1", 0.0);
    s.append("safety", 0.0);
    s.append("watchdog", 0.0);
  }
  const auto r = evaluate_saturation(sc, s);
  ASSERT_TRUE(r.has_value());
  // Rows 150..159 (0.10 s) and 300..349 (0.50 s): 0.60 s; the 100 + 51 resting rows are not counted.
  EXPECT_NEAR(r->saturated_s(), 0.60, 1e-9);
  for (int k = 1; k <= 4; ++k) EXPECT_NEAR(r->rotor_saturated_s(k), 0.60, 1e-9);
  EXPECT_NEAR(r->figures.at("command_at_limit_s"), 0.60, 1e-9);
}

TEST(SaturationTest, LimitsAreCriteria) {
  TempDir dir;
  Scenario sc = load_scenario(dir.write("limits.yaml", R"(simulation: {duration_s: 3}
analysis:
  limits: {max_saturated_s: 1.5, max_rotor_saturated_s: 1.0, max_tilt_saturated_s: 0.2, max_rms_u1_deviation_n: 0.5}
)"),
                              hosts::test_resolvers());
  ASSERT_TRUE(sc.limits.has_value());
  ASSERT_EQ(sc.limits->criteria.size(), 7u);
  const auto r = evaluate_saturation(sc, saturation_series());
  ASSERT_TRUE(r.has_value());
  EXPECT_FALSE(r->passed);
  std::map<std::string, bool> verdict;
  for (const auto& c : r->criteria) verdict[c.criterion.figure] = c.passed;
  EXPECT_TRUE(verdict.at("saturated_s"));  // 1.4 <= 1.5
  EXPECT_TRUE(verdict.at("rotor1_saturated_s"));
  EXPECT_FALSE(verdict.at("rotor2_saturated_s"));  // 1.3 > 1.0
  EXPECT_TRUE(verdict.at("rotor3_saturated_s"));
  EXPECT_FALSE(verdict.at("rotor4_saturated_s"));
  EXPECT_TRUE(verdict.at("tilt_saturated_s"));
  EXPECT_FALSE(verdict.at("rms_u1_deviation_n"));  // 1 N > 0.5 N

  const auto json_path = dir.file("metrics.json");
  write_metrics_json(json_path, sc, {}, std::nullopt, r);
  const auto j = nlohmann::json::parse(read_text(json_path));
  EXPECT_EQ(j.at("passed"), false);
  EXPECT_NEAR(j.at("saturation").at("figures").at("rotor2_saturated_s").get<double>(), 1.3, 1e-9);
  EXPECT_EQ(j.at("saturation").at("criteria").size(), 7u);
  const std::string table = format_step_table(sc, {}, std::nullopt, r);
  EXPECT_NE(table.find("rotor2_saturated_s"), std::string::npos) << table;
  EXPECT_NE(table.find("FAIL"), std::string::npos) << table;
}

TEST(SaturationTest, ColumnsRoundTripThroughTrajectoryCsv) {
  TempDir dir;
  const std::string path = dir.file("trajectory.csv");
  {
    TrajectoryWriter w(path);
    model::State airborne;  // in the air: motors at omega_min on the ground would be motors off
    airborne.p_W.z() = 1.0;
    for (int k = 0; k < 20; ++k) {
      ControlColumns c = ControlColumns::none();
      c.rotor_saturated = {false, k < 5, false, k >= 15};
      c.tilt_saturated = k == 7;
      w.write(k / 100.0, airborne, Eigen::Vector4d::Zero(), c);
    }
    w.close();
  }
  const Series s = read_series(path);
  Scenario sc;
  const auto r = evaluate_saturation(sc, s);
  ASSERT_TRUE(r.has_value());
  EXPECT_NEAR(r->rotor_saturated_s(2), 0.05, 1e-12);
  EXPECT_NEAR(r->rotor_saturated_s(4), 0.05, 1e-12);
  EXPECT_NEAR(r->saturated_s(), 0.10, 1e-12);
  EXPECT_NEAR(r->tilt_saturated_s(), 0.01, 1e-12);
  EXPECT_FALSE(r->figures.count("rms_u1_deviation_n"));  // U1 is NaN without a controller

  // A trajectory without the columns (written before they existed) still loads; no saturation figures.
  const std::string old_path = dir.write("old.csv",
                                         "t,x,y,z,roll,pitch,yaw,x_des,y_des,z_des,roll_des,pitch_des,yaw_des\n"
                                         "0,0,0,0,0,0,0,0,0,0,0,0,0\n");
  EXPECT_FALSE(evaluate_saturation(sc, read_series(old_path)).has_value());
}

TEST(SaturationTest, CommandAtLimitIsMeasuredFromTheCommandsAtThePlant) {
  // 100 Hz, 101 rows; the vehicle's limits 0..12000 rad/s. Rotor 3's command reaches omega_max on rows
  // 20..29 (10 rows), rotor 1's goes beyond it on rows 25..34 (overlapping: rows 20..34, 15 in all);
  // rotor 2 is commanded 0 (omega_min) on rows 60..64 (5), but rows 62..64 are the safety command and
  // row 63 the watchdog's too: 2 rows count. Rows 0..1 have no controller status yet (U1 NaN) and
  // commands of 0: not counted. The controller reported nothing (its flags all 0).
  Scenario sc;
  ASSERT_EQ(sc.vehicle.motor.omega_min_rad_s, 0.0);
  ASSERT_EQ(sc.vehicle.motor.omega_max_rad_s, 12000.0);
  Series s;
  for (int k = 0; k <= 100; ++k) {
    s.t_s.push_back(k / 100.0);
    for (const char* flag : {"sat1", "sat2", "sat3", "sat4", "tilt_sat"}) s.append(flag, 0.0);
    const bool started = k >= 2;
    s.append("U1", started ? 19.0 : std::numeric_limits<double>::quiet_NaN());
    s.append("cmd1", !started ? 0.0 : k >= 25 && k < 35 ? 12500.0 : 5000.0);
    s.append("cmd2", !started ? 0.0 : k >= 60 && k < 65 ? 0.0 : 5000.0);
    s.append("cmd3", !started ? 0.0 : k >= 20 && k < 30 ? 12000.0 : 11999.999);
    s.append("cmd4", !started ? 0.0 : 5000.0);
    s.append("safety", k >= 62 && k < 65 ? 1.0 : 0.0);
    s.append("watchdog", k == 63 ? 1.0 : 0.0);
  }
  const auto r = evaluate_saturation(sc, s);
  ASSERT_TRUE(r.has_value());
  EXPECT_NEAR(r->figures.at("command_at_limit_s"), 0.17, 1e-12);
  EXPECT_EQ(r->saturated_s(), 0.0);
  const std::string w = saturation_warning(*r);
  EXPECT_NE(w.find("at the plant was at omega_min/omega_max for 0.170 s (the controller reports no saturation)"),
            std::string::npos)
      << w;
}

TEST(TrajectoryCsvTest, TheControllersOwnFiguresAreNamedColumns) {
  // The first row's status fixes the out.<name> columns; a row whose status declares other names (a
  // replaced controller) or none (before the first step) has NaN there.
  TempDir dir;
  const std::string path = dir.file("trajectory.csv");
  const std::vector<std::string> names = {"error.z", "rate_des.p", "bad,name"};
  const std::vector<std::string> other = {"thrust_N"};
  {
    TrajectoryWriter w(path);
    for (int k = 0; k < 4; ++k) {
      ControlColumns c = ControlColumns::none();
      const std::vector<double> values = {0.25 * k, -1.0 / 3.0, 7.0};
      const std::vector<double> one = {9.5};
      if (k != 2) {
        c.output_names = names;
        c.outputs = values;
      } else {
        c.output_names = other;
        c.outputs = one;
      }
      w.write(k / 100.0, model::State{}, Eigen::Vector4d::Zero(), c);
    }
    w.close();
  }
  const std::vector<std::string> lines = lines_of(read_text(path));
  ASSERT_EQ(lines.size(), 5u);
  const std::vector<std::string> header = split(lines[0]);
  ASSERT_EQ(header.size(), TrajectoryWriter::columns().size() + 3);
  EXPECT_EQ(header[header.size() - 3], "out.error.z");
  EXPECT_EQ(header[header.size() - 2], "out.rate_des.p");
  EXPECT_EQ(header[header.size() - 1], "out.bad_name");  // a comma would split the column
  const auto last3 = [&](int row) {
    const std::vector<std::string> cells = split(lines[row + 1]);
    EXPECT_EQ(cells.size(), header.size()) << row;
    return std::vector<std::string>(cells.end() - 3, cells.end());
  };
  EXPECT_EQ(last3(1), (std::vector<std::string>{"0.25", "-0.3333333333333333", "7"}));
  EXPECT_EQ(last3(2), (std::vector<std::string>{"nan", "nan", "nan"}));
  EXPECT_EQ(last3(3), (std::vector<std::string>{"0.75", "-0.3333333333333333", "7"}));

  // Open loop (no status, no names): the fixed columns only.
  const std::string plain = dir.file("plain.csv");
  {
    TrajectoryWriter w(plain);
    w.write(0.0, model::State{}, Eigen::Vector4d::Zero(), ControlColumns::none());
    w.close();
  }
  EXPECT_EQ(split(lines_of(read_text(plain))[0]), TrajectoryWriter::columns());
}

TEST(StepReportTest, MissingChannelIsALogicError) {
  const Series series = first_order_series(0.0, 0.5, 10.0);
  StepSpec s = z_step(0.0, {});
  s.channel = "yaw";
  EXPECT_THROW(evaluate_steps({s}, series), std::logic_error);
}

TEST(StepReportTest, MetricsJsonHasTheDocumentedKeys) {
  const Series series = first_order_series(1.0, 0.5, 10.0);
  Scenario sc;
  sc.name = "report_test";
  sc.description = "hand-made series";
  StepSpec pass = z_step(1.0, {{"t95_s", 1.4, 1.6}, {"overshoot_pct", std::nullopt, 1.0}});
  pass.reference_source = "made up";
  pass.reference = {{"t95_s", 1.5}};
  StepSpec fail = z_step(1.0, {{"peak_time_s", 0.0, 10.0}});
  StepSpec roll;
  roll.channel = "roll";  // zero step: every figure empty
  const auto results = evaluate_steps({pass, fail, roll}, series);

  TempDir dir;
  const std::string path = dir.file("metrics.json");
  write_metrics_json(path, sc, results);
  const nlohmann::json j = nlohmann::json::parse(read_text(path));

  EXPECT_EQ(j.at("scenario"), "report_test");
  EXPECT_EQ(j.at("passed"), false);
  ASSERT_TRUE(j.at("steps").is_array());
  ASSERT_EQ(j.at("steps").size(), 3u);

  const auto& s0 = j["steps"][0];
  EXPECT_EQ(s0.at("channel"), "z");
  EXPECT_EQ(s0.at("passed"), true);
  EXPECT_EQ(s0.at("target"), 10.0);
  EXPECT_EQ(s0.at("t_step_s"), 1.0);
  const auto& figs = s0.at("figures");
  for (const auto& name : analysis::figure_names()) EXPECT_TRUE(figs.contains(name)) << name;
  EXPECT_EQ(figs.size(), analysis::figure_names().size());
  EXPECT_NEAR(figs.at("t95_s").get<double>(), 1.5, 1e-12);
  EXPECT_EQ(figs.at("overshoot_pct"), 0.0);
  EXPECT_TRUE(figs.at("peak_time_s").is_null());
  ASSERT_EQ(s0.at("criteria").size(), 2u);
  const auto& c0 = s0["criteria"][0];
  EXPECT_EQ(c0.at("figure"), "t95_s");
  EXPECT_EQ(c0.at("min"), 1.4);
  EXPECT_EQ(c0.at("max"), 1.6);
  EXPECT_NEAR(c0.at("value").get<double>(), 1.5, 1e-12);
  EXPECT_EQ(c0.at("passed"), true);
  const auto& c1 = s0["criteria"][1];
  EXPECT_TRUE(c1.at("min").is_null());
  EXPECT_EQ(c1.at("max"), 1.0);
  EXPECT_EQ(s0.at("reference").at("source"), "made up");
  EXPECT_EQ(s0.at("reference").at("t95_s"), 1.5);

  const auto& s1 = j["steps"][1];
  EXPECT_EQ(s1.at("passed"), false);
  EXPECT_TRUE(s1.at("criteria")[0].at("value").is_null());
  EXPECT_EQ(s1.at("criteria")[0].at("passed"), false);
  EXPECT_FALSE(s1.contains("reference"));

  const auto& s2 = j["steps"][2];
  EXPECT_EQ(s2.at("channel"), "roll");
  EXPECT_EQ(s2.at("passed"), true);
  EXPECT_TRUE(s2.at("criteria").is_array());
  EXPECT_TRUE(s2.at("criteria").empty());
  for (const auto& name : analysis::figure_names()) EXPECT_TRUE(s2.at("figures").at(name).is_null()) << name;

  // All passing: top-level passed is true.
  write_metrics_json(path, sc, {results[0], results[2]});
  EXPECT_EQ(nlohmann::json::parse(read_text(path)).at("passed"), true);
}

TEST(StepReportTest, MetricsJsonToAnUnwritablePathThrows) {
  TempDir dir;
  const Scenario sc;
  EXPECT_THROW(write_metrics_json(dir.file("no/such/dir/metrics.json"), sc, {}), std::runtime_error);
}

TEST(StepReportTest, TableShowsVerdicts) {
  const Series series = first_order_series(1.0, 0.5, 10.0);
  Scenario sc;
  sc.name = "table";
  const auto results = evaluate_steps({z_step(1.0, {{"t95_s", 1.4, 1.6}}), z_step(1.0, {{"t95_s", 2, 3}})}, series);
  const std::string table = format_step_table(sc, results);
  EXPECT_NE(table.find("scenario table"), std::string::npos) << table;
  EXPECT_NE(table.find("PASS"), std::string::npos) << table;
  EXPECT_NE(table.find("FAIL"), std::string::npos) << table;
  EXPECT_NE(table.find("[1.4, 1.6]"), std::string::npos) << table;
}

}  // namespace
}  // namespace quadcosim::io
