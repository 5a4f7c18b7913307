// The `controller:` section of a scenario (docs/scenarios.md): a registered type with its parameters
// (and the gains sections of other types, checked), an FMU with its inputs, outputs and parameters, a
// class written in Python (made by the caller's ScenarioResolvers) or a SITL firmware; the
// FMU of a `plant:` section; and the controller --controller names, written into a parsed file
// (parse_controller_choice, set_controller_type in io/scenario.hpp). Every reader throws ConfigError
// naming the file, the key and the value.
#pragma once

#include <filesystem>
#include <memory>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "io/scenario.hpp"
#include "io/yaml_reader.hpp"

namespace quadcosim::io {

/// The parameters of `s` (directly under it and in the gains sections named after registered types)
/// applied to `c`; with `out`, also the values read, by name.
void read_parameters(YamlSection& s, control::ControllerConfig& c,
                     std::vector<std::pair<std::string, control::ParameterValue>>* out);

/// The `fmu`, `inputs`, `outputs` and `parameters` keys of a `plant:` or `controller:` section; a
/// relative path is taken from `folder` (the scenario file's).
FmuSpec read_fmu_spec(YamlSection& s, const std::filesystem::path& folder);

/// The FMU of `spec` as plant dynamics, made by resolvers.fmu; its refusals are ConfigErrors at their
/// key under `s`.
std::shared_ptr<const sim::ExternalDynamicsFactory> make_plant_fmu(YamlSection& s, const FmuSpec& spec,
                                                                   const ScenarioResolvers& resolvers);

/// The FMU of `spec` as the controller of `vehicle`, made by resolvers.fmu; its refusals are
/// ConfigErrors at their key under `s`.
std::shared_ptr<const control::Controller> make_controller_fmu(YamlSection& s, const FmuSpec& spec,
                                                               const model::VehicleParams& vehicle,
                                                               const ScenarioResolvers& resolvers);

/// Why an FMU controller's inputs of extra sensors do not fit the sensors the scenario's vehicle
/// carries, or empty.
std::string controller_sensors_error(const Scenario& sc, const ScenarioResolvers& resolvers);

/// A `controller:` section, for `vehicle`; `folder` is the scenario file's (FMU paths, Python imports,
/// firmware binaries); `fmu_spec`, when given, receives an FMU controller's spec; an FMU or a Python
/// class is made by `resolvers`.
control::ControllerConfig read_controller(YamlSection& s, const model::VehicleParams& vehicle,
                                          const std::filesystem::path& folder, std::optional<FmuSpec>* fmu_spec,
                                          const ScenarioResolvers& resolvers);

}  // namespace quadcosim::io
