// Test vehicles beyond four rotors for the FMU export's tests (fmu_config_test, fmu_rotors_test).
#pragma once

#include <Eigen/Core>
#include <array>
#include <cstddef>

#include "model/vehicle_presets.hpp"

namespace quadcosim::fmi::test {

/// The custom coaxial X8 of scenarios/examples/octo_custom_step.yaml: the firefly preset's motors and
/// propellers, 2.4 kg, two rotors (above and below, opposite spins) at each corner of a 0.495 m square.
inline model::VehicleParams octo_x8() {
  model::VehicleParams v = model::find_vehicle_preset("firefly")->params;
  v.mass_kg = 2.4;
  v.set_layout(model::RotorLayout::kCustom);
  v.rotor_count = 8;
  const double a = 0.2475;
  const std::array<Eigen::Vector3d, 8> p = {Eigen::Vector3d(a, a, 0.04),
                                            {a, a, -0.04},
                                            {a, -a, 0.04},
                                            {a, -a, -0.04},
                                            {-a, -a, 0.04},
                                            {-a, -a, -0.04},
                                            {-a, a, 0.04},
                                            {-a, a, -0.04}};
  const std::array<int, 8> spin = {1, -1, -1, 1, 1, -1, -1, 1};
  for (std::size_t i = 0; i < 8; ++i) {
    v.rotor_positions_m[i] = p[i];
    v.spin[i] = spin[i];
  }
  return v;
}

}  // namespace quadcosim::fmi::test
