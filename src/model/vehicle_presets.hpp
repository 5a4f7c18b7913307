// Ready vehicles: published parameter sets a scenario names by `vehicle: {preset: NAME}` (other keys
// of the section then override single values) and `quadcosim params --vehicle --preset NAME` prints.
// Each preset states where every number comes from (docs/model.md, "Vehicle presets").
#pragma once

#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "model/vehicle_params.hpp"

namespace quadcosim::model {

struct VehiclePreset {
  std::string_view name;         ///< what `preset:` takes
  std::string_view description;  ///< one line: the vehicle
  std::string_view sources;      ///< the publications (and derivations) its numbers come from
  VehicleParams params;
};

/// Every preset, the paper's vehicle first.
std::span<const VehiclePreset> vehicle_presets();

/// The preset named `name`, or nullptr.
const VehiclePreset* find_vehicle_preset(std::string_view name);

/// The names, the paper's vehicle first (for choices and flag checks).
std::vector<std::string> vehicle_preset_list();

/// "paper, crazyflie2, ...": the names, for messages.
std::string vehicle_preset_names();

}  // namespace quadcosim::model
