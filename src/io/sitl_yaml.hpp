// A scenario's `controller: {sitl: {...}}` section (docs/scenarios.md, docs/sitl.md): a flight stack's
// SITL build flown as the controller.
#pragma once

#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include "control/controller.hpp"
#include "io/yaml_reader.hpp"
#include "model/vehicle_params.hpp"
#include "sensors/sensor_set.hpp"

namespace quadcosim::io {

/// The environment variable that names ArduPilot's SITL executable when the section gives no binary.
inline constexpr const char* kArduPilotSitlEnv = "QUADCOSIM_ARDUPILOT_SITL";
/// The environment variable that names PX4's SITL executable (build/px4_sitl_default/bin/px4).
inline constexpr const char* kPx4SitlEnv = "QUADCOSIM_PX4_SITL";
/// The environment variable that names Betaflight's SITL executable (obj/main/betaflight_SITL.elf).
inline constexpr const char* kBetaflightSitlEnv = "QUADCOSIM_BETAFLIGHT_SITL";

/// The SITL controller the `sitl` section under `s` describes, for `vehicle`; relative paths are taken
/// from `folder` (the scenario file's). Throws ConfigError at the key that is wrong (a missing binary
/// names the environment variable too).
std::shared_ptr<const control::Controller> read_sitl_controller(YamlSection& s, const model::VehicleParams& vehicle,
                                                                const std::filesystem::path& folder);

/// For a scenario flown by PX4 (`controller: {sitl: {firmware: px4}}` under `root`): the sensors PX4
/// needs that the file does not configure are added to the YAML tree before it is read (docs/sitl.md,
/// "What PX4 needs"): environment.site (PX4's default home, Zurich), sensors.imu noise,
/// sensors.magnetometer (the field of the World Magnetic Model there), sensors.barometer and
/// sensors.gnss, each with noise, at rates that land on control ticks. A magnetometer is added only at
/// that site (elsewhere the file must give the site's field: ConfigError naming the key). Returns the
/// names of what was added (for a note on the console). Nothing for other controllers.
std::vector<std::string> add_px4_sensors(YamlSection& root, double plant_rate_hz, int controller_divider);

/// The PX4 controller of `controller` told its site (the GNSS's origin, for takeoff altitudes and goto
/// positions) and what add_px4_sensors added (it notes them on stderr when it starts), or `controller`
/// unchanged when it is not PX4's.
std::shared_ptr<const control::Controller> with_px4_site(std::shared_ptr<const control::Controller> controller,
                                                         const sensors::SensorSet& sensors,
                                                         std::vector<std::string> added);

}  // namespace quadcosim::io
