// `controller: {python: "module:Class"}` in a scenario: resolved through the factory the caller hands
// io (ScenarioResolvers::python: whatever hosts a Python interpreter), refused by name without one.
// The factory here is a C++ stand-in (it returns example_pd), so these tests need no Python.
#include <gtest/gtest.h>
#include <stdlib.h>

#include <filesystem>
#include <fstream>
#include <stdexcept>
#include <string>

#include "controllers/registry.hpp"
#include "io/scenario.hpp"

namespace quadcosim::io {
namespace {

namespace fs = std::filesystem;

class PythonScenarioTest : public ::testing::Test {
 protected:
  void SetUp() override {
    std::string pattern = (fs::temp_directory_path() / "quadcosim_python_scenario_XXXXXX").string();
    ASSERT_NE(mkdtemp(pattern.data()), nullptr);
    dir_ = pattern;
  }
  void TearDown() override {
    std::error_code ec;
    fs::remove_all(dir_, ec);
  }
  std::string write(const std::string& text) const {
    const fs::path p = dir_ / "scenario.yaml";
    std::ofstream(p) << text;
    return p.string();
  }
  /// The message of the ConfigError loading `text` throws ("" when it loads).
  std::string error_of(const std::string& text) const {
    try {
      load_scenario(write(text), resolvers_);
    } catch (const ConfigError& e) {
      return e.what();
    }
    return "";
  }

  fs::path dir_;
  ScenarioResolvers resolvers_;  ///< no FMUs; the Python factory each test sets
};

TEST_F(PythonScenarioTest, WithoutAnInterpreterTheKeyIsRefusedByName) {
  const std::string e = error_of("controller: {python: \"my_controllers:AltitudePD\", z_des: 1}\n");
  EXPECT_NE(e.find("scenario.yaml: controller.python: this quadcosim was built without Python"), std::string::npos)
      << e;
  EXPECT_NE(error_of("controller: {type: python, python: \"m:C\"}\n").find("built without Python"), std::string::npos);
}

TEST_F(PythonScenarioTest, TheHookGetsTargetFolderAndVehicleAndTheSectionItsParameters) {
  std::string target;
  fs::path folder;
  double mass = 0.0;
  resolvers_.python = [&](const std::string& t, const fs::path& f, const model::VehicleParams& v) {
    target = t;
    folder = f;
    mass = v.mass_kg;
    return controllers::make_config("example_pd", v).controller;
  };
  const Scenario sc = load_scenario(write(R"(
vehicle: {mass_kg: 2.5}
controller:
  type: python
  python: "my_controllers:Outer.Inner"
  z_des: 3
  position.kp: 2.5
schedule:
  - {at_s: 1, set: {position.kd: 0.5}}
)"),
                                    resolvers_);
  EXPECT_EQ(target, "my_controllers:Outer.Inner");
  EXPECT_EQ(folder, dir_);
  EXPECT_EQ(mass, 2.5);
  EXPECT_EQ(sc.controller.type(), "example_pd");  // what the hook made
  EXPECT_EQ(std::get<double>(*control::get_parameter(sc.controller, "position.kp")), 2.5);
  EXPECT_EQ(std::get<double>(*control::get_parameter(sc.controller, "z_des")), 3.0);
  ASSERT_EQ(sc.schedule.size(), 1u);
  EXPECT_EQ(sc.schedule[0].name, "position.kd");
  // The class's parameters are checked against what the hook made: a range or a name.
  const std::string base = "controller: {python: \"m:C\", ";
  EXPECT_NE(error_of(base + "position.kp: -1}\n").find("controller.position.kp: position.kp must be in [0, 1000]"),
            std::string::npos);
  EXPECT_NE(error_of(base + "kp_zz: 1}\n").find("controller.kp_zz: unknown parameter 'kp_zz'"), std::string::npos);
}

TEST_F(PythonScenarioTest, TheHookRefusingIsAConfigErrorAtTheKey) {
  resolvers_.python = [](const std::string&, const fs::path&,
                         const model::VehicleParams&) -> std::shared_ptr<const control::Controller> {
    throw std::invalid_argument("cannot import m:C: ModuleNotFoundError: No module named 'm'");
  };
  const std::string e = error_of("controller: {python: \"m:C\"}\n");
  EXPECT_NE(e.find("controller.python: got 'm:C': cannot import m:C: ModuleNotFoundError"), std::string::npos) << e;
}

TEST_F(PythonScenarioTest, WhatCannotStandBesideIt) {
  resolvers_.python = [](const std::string&, const fs::path&, const model::VehicleParams& v) {
    return controllers::make_config("example_pd", v).controller;
  };
  EXPECT_NE(error_of("controller: {type: paper, python: \"m:C\"}\n").find("controller.type: got 'paper' beside python"),
            std::string::npos);
  EXPECT_NE(error_of("controller: {fmu: x.fmu, python: \"m:C\"}\n").find("controller.fmu: beside python"),
            std::string::npos);
  EXPECT_NE(error_of("controller: {type: python}\n").find("controller.python: missing; expected"), std::string::npos);
  EXPECT_NE(error_of("controller: {python: \"m:C\", inputs: {}}\n").find("controller.inputs: belongs to an FMU"),
            std::string::npos);
  EXPECT_NE(error_of("controller: {python: \"m:C\"}\nschedule: [{at_s: 0, set: {python: \"m:D\"}}]\n")
                .find("schedule[0].set.python: the controller cannot change during a run"),
            std::string::npos);
}

}  // namespace
}  // namespace quadcosim::io
