// A scenario's `controller: {sitl: {...}}` section (docs/scenarios.md, docs/sitl.md): a flight stack's
// SITL build flown as the controller.
#pragma once

#include <filesystem>
#include <memory>

#include "control/controller.hpp"
#include "io/yaml_reader.hpp"
#include "model/vehicle_params.hpp"

namespace quadcosim::io {

/// The environment variable that names ArduPilot's SITL executable when the section gives no binary.
inline constexpr const char* kArduPilotSitlEnv = "QUADCOSIM_ARDUPILOT_SITL";

/// The SITL controller the `sitl` section under `s` describes, for `vehicle`; relative paths are taken
/// from `folder` (the scenario file's). Throws ConfigError at the key that is wrong (a missing binary
/// names the environment variable too).
std::shared_ptr<const control::Controller> read_sitl_controller(YamlSection& s, const model::VehicleParams& vehicle,
                                                                const std::filesystem::path& folder);

}  // namespace quadcosim::io
