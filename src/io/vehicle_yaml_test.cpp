// The vehicle's rotors in YAML (layouts, a custom rotor list, spin signs one per rotor) and the
// per-rotor aerodynamics coefficients a file sets without switching them on.
#include <gtest/gtest.h>

#include <string>

#include "io/scenario.hpp"
#include "io/vehicle_yaml.hpp"
#include "io/yaml_reader.hpp"
#include "model/mixer.hpp"

namespace quadcosim::io {
namespace {

model::VehicleParams read(const std::string& yaml) {
  YamlSection s(YAML::Load(yaml), "v.yaml", "vehicle");
  model::VehicleParams v;
  read_vehicle(s, v);
  return v;
}

std::string refusal(const std::string& yaml) {
  try {
    read(yaml);
  } catch (const ConfigError& e) {
    return e.what();
  }
  return "";
}

TEST(VehicleYaml, AStandardLayoutSetsItsRotorCountAndAlternatingSigns) {
  const model::VehicleParams hex = read("layout: hex_x\n");
  EXPECT_EQ(hex.layout, model::RotorLayout::kHexX);
  EXPECT_EQ(hex.rotor_count, 6);
  for (int i = 0; i < 6; ++i) EXPECT_EQ(hex.spin[static_cast<std::size_t>(i)], i % 2 == 0 ? 1 : -1);
  const model::VehicleParams octo = read("layout: octo_plus\nspin: [-1, 1, -1, 1, -1, 1, -1, 1]\n");
  EXPECT_EQ(octo.rotor_count, 8);
  EXPECT_EQ(octo.spin[0], -1);
  // A preset's signs carry over unless the layout changes the count.
  const model::VehicleParams ff = read("preset: firefly\nmass_kg: 1.6\n");
  EXPECT_EQ(ff.rotor_count, 6);
  EXPECT_EQ(ff.spin[0], -1);
}

TEST(VehicleYaml, ACustomRotorListIsReadInOrder) {
  const model::VehicleParams v = read(R"(rotors:
  - {position_m: [0.3, 0.0, 0.02], spin: 1}
  - {position_m: [0.0, -0.3, 0.0], spin: -1}
  - {position_m: [-0.3, 0.0, 0.0], spin: 1}
  - {position_m: [0.0, 0.3, 0.0], spin: -1}
  - {position_m: [0.1, 0.1, 0.0], spin: -1}
)");
  EXPECT_EQ(v.layout, model::RotorLayout::kCustom);
  EXPECT_EQ(v.rotor_count, 5);
  EXPECT_EQ(model::rotor_position_B(v, 0), Eigen::Vector3d(0.3, 0.0, 0.02));
  EXPECT_EQ(model::rotor_position_B(v, 4), Eigen::Vector3d(0.1, 0.1, 0.0));
  EXPECT_EQ(v.spin[4], -1);
}

TEST(VehicleYaml, BadRotorSetsAreRefusedByName) {
  std::string e = refusal("layout: hex_plus\nspin: [1, -1, 1, -1]\n");
  EXPECT_NE(e.find("vehicle.spin: got a list of 4 entries, expected 6"), std::string::npos) << e;
  e = refusal(
      "rotors:\n  - {position_m: [0.3, 0, 0], spin: 1}\n  - {position_m: [0, 0.3, 0], spin: -1}\n"
      "  - {position_m: [-0.3, 0, 0], spin: 1}\n");
  EXPECT_NE(e.find("vehicle.rotors: got 3 rotors, expected 4 to 8"), std::string::npos) << e;
  e = refusal("layout: custom\n");
  EXPECT_NE(e.find("without rotors:"), std::string::npos) << e;
  e = refusal("layout: hex_x\nrotors:\n  - {position_m: [0.3, 0, 0], spin: 1}\n");
  EXPECT_NE(e.find("vehicle.layout: got 'hex_x' beside rotors:"), std::string::npos) << e;
  e = refusal(
      "rotors:\n  - {position_m: [0.3, 0, 0], spin: 2}\n  - {position_m: [0, 0.3, 0], spin: -1}\n"
      "  - {position_m: [-0.3, 0, 0], spin: 1}\n  - {position_m: [0, -0.3, 0], spin: -1}\n");
  EXPECT_NE(e.find("vehicle.rotors[0].spin: got '2'"), std::string::npos) << e;
  e = refusal(
      "rotors:\n  - {position_m: [0.3, 0, 0], spin: 1}\n  - {position_m: [0.3, 0, 0], spin: -1}\n"
      "  - {position_m: [-0.3, 0, 0], spin: 1}\n  - {position_m: [0, -0.3, 0], spin: -1}\n");
  EXPECT_NE(e.find("vehicle.rotors: must be at distinct positions, got rotors 1 and 2"), std::string::npos) << e;
  e = refusal("layout: hex_x\nspin: [1, 1, 1, 1, 1, 1]\n");
  EXPECT_NE(e.find("singular"), std::string::npos) << e;
  EXPECT_NE(e.find("hex_x"), std::string::npos) << e;
}

TEST(VehicleYaml, ARotorAeroCoefficientSetWithoutTheSwitchIsRefused) {
  std::string e = refusal("aero: {rotor_drag_k_d: 1e-4}\n");
  EXPECT_NE(e.find("vehicle.aero.rotor_drag_k_d: set to 0.0001 while aero.rotor_aero is false"), std::string::npos)
      << e;
  e = refusal("aero: {rotor_aero: false, flapping_k_flap: 1e-6}\n");
  EXPECT_NE(e.find("vehicle.aero.flapping_k_flap"), std::string::npos) << e;
  // With the switch on it is read; zero is harmless; a preset carries its own switched off.
  EXPECT_EQ(read("aero: {rotor_aero: true, inflow_k_z: 2e-4}\n").aero.inflow_k_z, 2e-4);
  EXPECT_EQ(read("aero: {translational_lift_k_h: 0}\n").aero.translational_lift_k_h, 0.0);
  const model::VehicleParams cf = read("preset: crazyflie2\n");
  EXPECT_GT(cf.aero.rotor_drag_k_d, 0.0);
  EXPECT_EQ(cf.aero.rotor_aero, model::RotorAero::kOff);
}

}  // namespace
}  // namespace quadcosim::io
