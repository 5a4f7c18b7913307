// Scenarios with FMUs: `plant: {fmu: ...}` and `controller: {fmu: ...}` read, resolved and refused
// by key (io/scenario.cpp), and the point-mass test FMU (tests/fmi/point_mass) flown as the plant
// under the paper controller's altitude channel, against quadcosim's own plant in vertical flight.
#include <gtest/gtest.h>
#include <stdlib.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "hosts/scenario_resolvers_test_support.hpp"
#include "io/scenario.hpp"
#include "sim/simulation.hpp"

namespace quadcosim::io {
namespace {

namespace fs = std::filesystem;

const fs::path kFmuDir = QUADCOSIM_TEST_FMU_DIR;

class FmuScenario : public ::testing::Test {
 protected:
  void SetUp() override {
    std::string pattern = (fs::temp_directory_path() / "quadcosim_fmu_scenario_XXXXXX").string();
    ASSERT_NE(mkdtemp(pattern.data()), nullptr);
    dir_ = pattern;
    fs::create_directories(dir_ / "fmus");
    fs::copy_file(kFmuDir / "point_mass.fmu", dir_ / "fmus" / "point_mass.fmu");
    fs::copy_file(kFmuDir / "sensor_echo.fmu", dir_ / "fmus" / "sensor_echo.fmu");
  }
  void TearDown() override {
    std::error_code ec;
    fs::remove_all(dir_, ec);
  }
  /// Writes `text` as a scenario file in the temporary folder; its path.
  std::string write(const std::string& text) {
    const fs::path p = dir_ / "scenario.yaml";
    std::ofstream(p) << text;
    return p.string();
  }
  /// The message load_scenario refuses `text` with ("" when it is not refused).
  std::string refusal(const std::string& text) {
    try {
      load_scenario(write(text), hosts::test_resolvers());
    } catch (const ConfigError& e) {
      return e.what();
    }
    return "";
  }
  fs::path dir_;
};

/// The point mass's physics as the paper's vehicle with a larger thrust coefficient (its hover speed,
/// about 1390 rad/s, stays below the 2000 rad/s it warns above), hovering at 1 m, stepping to 2 m.
const char* kVertical = R"(
vehicle: {kt_N_per_rad2_s2: 2.5e-6}
simulation: {duration_s: 12}
initial: {position_m: [0, 0, 1], hover: true}
controller: {mode: attitude, z_des: 1}
schedule: [{at_s: 0.5, set: {z_des: 2.0}}]
)";
const char* kPointMassPlant = R"(
plant:
  fmu: fmus/point_mass.fmu
  parameters: {mass_kg: 1.96, k_thrust: 2.5e-6, g: 9.81, z0: 1}
)";

std::vector<model::State> fly(const Scenario& sc) {
  std::vector<model::State> states;
  sim::Simulation s(sc.simulation, sc.vehicle, initial_state(sc), sc.controller, sc.schedule);
  s.run([&](const sim::TickRecord& r) { states.push_back(r.state); });
  return states;
}

TEST_F(FmuScenario, PointMassPlantFliesThePaperAltitudeChannelAsTheNativePlantDoes) {
  const Scenario native = load_scenario(write(kVertical), hosts::test_resolvers());
  const Scenario fmu = load_scenario(write(std::string(kVertical) + kPointMassPlant), hosts::test_resolvers());
  ASSERT_TRUE(fmu.simulation.plant.external);
  ASSERT_TRUE(fmu.plant_fmu);
  EXPECT_EQ(fmu.plant_fmu->path, (dir_ / "fmus/point_mass.fmu").lexically_normal().string());  // relative to the file
  const std::vector<model::State> a = fly(native), b = fly(fmu);
  ASSERT_EQ(a.size(), b.size());
  // In vertical flight the 6-DOF model's RK4 integrates a constant acceleration exactly, as the
  // point mass does in closed form: the two agree to rounding.
  double worst = 0.0;
  for (std::size_t i = 0; i < a.size(); ++i) {
    worst = std::max(worst, std::abs(a[i].p_W.z() - b[i].p_W.z()));
    ASSERT_NEAR(a[i].v_W.z(), b[i].v_W.z(), 1e-9) << "tick " << i;
    ASSERT_EQ(b[i].p_W.x(), 0.0);
  }
  EXPECT_LT(worst, 1e-9);
  // The step was flown: near 2 m at the end, the rotors near the hover speed sqrt(m g / (4 k_t)).
  EXPECT_NEAR(b.back().p_W.z(), 2.0, 0.02);  // within the paper's 2 % band of the step
  EXPECT_NEAR(b.back().omega_rad_s[0], std::sqrt(1.96 * 9.81 / (4 * 2.5e-6)), 5.0);
}

TEST_F(FmuScenario, BadKeysAreRefusedNamingTheKey) {
  const std::string base = "controller: {z_des: 1}\n";
  auto expect = [&](const std::string& text, const std::string& words) {
    const std::string got = refusal(base + text);
    EXPECT_NE(got.find(words), std::string::npos) << "got: " << got;
  };
  expect("plant: {fmu: fmus/missing.fmu}", "plant.fmu: got 'fmus/missing.fmu': no such file");
  expect("plant: {inputs: {}}", "plant.fmu: missing");
  expect("plant: {fmu: fmus/point_mass.fmu, outputs: {p_W: [x, y, z]}}",
         "plant.outputs.p_W: point_mass.fmu has no variable 'x'");
  expect("plant: {fmu: fmus/point_mass.fmu, outputs: {v_W: ['p_W[1]', 'p_W[2]', 'p_W[3]']}}",
         "plant.outputs.v_W: point_mass.fmu: variable 'p_W[1]' has unit 'm', expected 'm/s'");
  expect("plant: {fmu: fmus/point_mass.fmu, outputs: {position: [a, b, c]}}", "plant.outputs.position: unknown signal");
  expect("plant: {fmu: fmus/point_mass.fmu, parameters: {mass: 2}}",
         "plant.parameters.mass: point_mass.fmu has no variable 'mass'");
  expect("plant: {fmu: fmus/point_mass.fmu, parameters: {mass_kg: heavy}}",
         "plant.parameters.mass_kg: got 'heavy', expected a finite number");
  expect("plant: {fmu: fmus/point_mass.fmu, input: {}}", "plant.input");
  expect("plant: {fmu: fmus/point_mass.fmu}\nenvironment: {wind_m_s: [2, 0, 0]}",
         "environment: acts inside quadcosim's own plant model only");
  expect("plant: {fmu: fmus/point_mass.fmu}\nfaults: [{at_s: 1, rotor: 2, efficiency: 0.5}]", "faults: acts inside");
  expect("plant: {fmu: fmus/point_mass.fmu}\nvehicle: {aero: {linear_drag_N_s_m: [0.1, 0.1, 0.2]}}",
         "vehicle.aero.linear_drag_N_s_m.x: acts inside");
  const std::string not_a_controller = refusal("controller: {fmu: fmus/point_mass.fmu}");
  EXPECT_NE(not_a_controller.find("controller.inputs.p_W: point_mass.fmu: variable 'p_W[1]' has causality output, "
                                  "expected input"),
            std::string::npos)
      << not_a_controller;
  const std::string typed = refusal("controller: {type: se3, fmu: fmus/point_mass.fmu}");
  EXPECT_NE(typed.find("controller.type: got 'se3' beside fmu"), std::string::npos) << typed;
  const std::string stray = refusal("controller: {type: paper, outputs: {}}");
  EXPECT_NE(stray.find("controller.outputs: belongs to an FMU controller"), std::string::npos) << stray;
}

TEST_F(FmuScenario, AControllerFmuWithSensorInputsNeedsTheSensorsOn) {
  // tests/fmi/sensor_echo: inputs of the magnetometer, the barometer and the GNSS.
  const std::string controller = "controller: {fmu: fmus/sensor_echo.fmu}\n";
  const std::string none = refusal(controller);
  EXPECT_NE(none.find("controller.fmu: sensor_echo.fmu has the input 'magnetometer.field[1]', but the vehicle carries "
                      "no magnetometer: turn it on with the scenario key sensors.magnetometer"),
            std::string::npos)
      << none;
  const std::string two = refusal(controller + "sensors: {magnetometer: {}, barometer: {}}\n");
  EXPECT_NE(two.find("controller.fmu: sensor_echo.fmu has the input 'gnss.fix', but the vehicle carries no gnss: turn "
                     "it on with the scenario key sensors.gnss"),
            std::string::npos)
      << two;
  const std::string all = controller + "sensors: {magnetometer: {}, barometer: {}, gnss: {}}\n";
  EXPECT_EQ(refusal(all), "");
  // The command line's --fmu is checked against the scenario's sensors too.
  Scenario sc = load_scenario(write(std::string(kVertical)), hosts::test_resolvers());
  try {
    use_controller_fmu(sc, FmuSpec{(dir_ / "fmus/sensor_echo.fmu").string(), {}}, "--fmu", hosts::test_resolvers());
    ADD_FAILURE() << "a controller FMU with sensor inputs was taken for a vehicle without the sensors";
  } catch (const ConfigError& e) {
    EXPECT_NE(std::string(e.what()).find("--fmu: fmu: sensor_echo.fmu has the input 'magnetometer.field[1]'"),
              std::string::npos)
        << e.what();
  }
  Scenario on = load_scenario(write(all), hosts::test_resolvers());
  use_controller_fmu(on, FmuSpec{(dir_ / "fmus/sensor_echo.fmu").string(), {}}, "--fmu", hosts::test_resolvers());
}

TEST_F(FmuScenario, TheCommandLinesFmuReplacesThePlant) {
  Scenario sc = load_scenario(write(std::string(kVertical)), hosts::test_resolvers());
  use_plant_fmu(sc, FmuSpec{(dir_ / "fmus/point_mass.fmu").string(), {}}, "--fmu", hosts::test_resolvers());
  ASSERT_TRUE(sc.simulation.plant.external);
  EXPECT_NE(sc.simulation.plant.external->describe().find("point_mass.fmu (model 'PointMass', FMI 2.0)"),
            std::string::npos);
  try {
    use_plant_fmu(sc, FmuSpec{(dir_ / "nothing.fmu").string(), {}}, "--fmu", hosts::test_resolvers());
    ADD_FAILURE() << "a missing FMU was taken";
  } catch (const ConfigError& e) {
    EXPECT_EQ(std::string(e.what()).rfind("--fmu: fmu: ", 0), 0u) << e.what();
  }
}

}  // namespace
}  // namespace quadcosim::io
