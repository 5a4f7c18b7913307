// The vehicle: a scenario's `vehicle:` section and vehicle files (`--vehicle`), read through the one
// parameter table (model::vehicle_parameters()): every number in its declared range, the layout and
// its rotors (a standard layout by name, a custom one as `rotors: [{position_m: [x, y, z], spin: 1},
// ...]`), then the rules between fields (model::validate). docs/model.md, "Vehicle parameters".
#pragma once

#include "model/vehicle_params.hpp"

namespace quadcosim::io {

class YamlSection;

/// Reads `root` (the `vehicle:` section, or a vehicle file's top level) over `v`. A `preset:` key
/// starts from that ready vehicle (model/vehicle_presets.hpp); the other keys then override its values.
/// A per-rotor aerodynamics coefficient (aero.rotor_drag_k_d, inflow_k_z, flapping_k_flap,
/// translational_lift_k_h) that the file itself sets non-zero while aero.rotor_aero is not true is
/// refused (it would act on nothing); presets may carry them switched off. Throws ConfigError naming the
/// key and the problem.
void read_vehicle(YamlSection& root, model::VehicleParams& v);

}  // namespace quadcosim::io
