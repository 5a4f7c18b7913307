// What resolves the controllers and plants a scenario names outside quadcosim: a co-simulation FMU
// (`plant: {fmu: ...}`, `controller: {fmu: ...}`, --fmu, --controller fmu:PATH) and a class written in
// Python (`controller: {python: module:Class}`, --controller python:MODULE:CLASS). io/ reads and checks
// the keys; what loads an FMU or imports a class is handed to it by whoever hosts the run (the CLI,
// the Python module, a test), which owns what the resolvers keep (the loaded FMUs, the interpreter).
#pragma once

#include <filesystem>
#include <functional>
#include <memory>
#include <string>

#include "control/controller.hpp"
#include "model/vehicle_params.hpp"
#include "sensors/sensor_set.hpp"
#include "sim/external_dynamics.hpp"

namespace quadcosim::io {

struct FmuSpec;

/// Makes the FMUs a scenario names. A refusal is an fmi::FmuError (the FMU file, at the key `fmu`) or an
/// fmi::MappingError (at the key it names); io/ turns it into the ConfigError naming the scenario key.
class FmuResolver {
 public:
  virtual ~FmuResolver() = default;
  /// The FMU of `spec` as plant dynamics.
  virtual std::shared_ptr<const sim::ExternalDynamicsFactory> plant(const FmuSpec& spec) const = 0;
  /// The FMU of `spec` as the controller of `vehicle`.
  virtual std::shared_ptr<const control::Controller> controller(const FmuSpec& spec,
                                                                const model::VehicleParams& vehicle) const = 0;
  /// Why `controller`, when it is an FMU this resolver made, takes inputs of extra sensors the vehicle
  /// does not carry (`carried`); empty when it fits or is no FMU.
  virtual std::string sensors_error(const control::Controller& controller, const sensors::SensorSet& carried) const = 0;
};

/// What resolves a scenario's `controller: {python: "module:Class"}` (or `type: python`): from the
/// target text, the scenario file's folder (imports look there first) and the vehicle the controller is
/// designed for, the configured controller. Throws to refuse (the message becomes the ConfigError at
/// controller.python).
using PythonControllerFactory = std::function<std::shared_ptr<const control::Controller>(
    const std::string& target, const std::filesystem::path& folder, const model::VehicleParams& vehicle)>;

/// What finds the source file of a Python controller's module ("module:Class" -> the file the
/// interpreter imported, "" when it cannot tell), for a run's provenance (io/provenance.hpp).
using PythonModuleLocator = std::function<std::string(const std::string& target)>;

/// The resolvers a caller hands to load_scenario and the functions beside it (io/scenario.hpp). One that
/// is missing refuses what it would resolve with a ConfigError that says so: no `python` (a build
/// without Python, or a host without an interpreter): "controller.python: this quadcosim was built
/// without Python ..."; no `fmu`: "fmu: ... cannot load FMUs here".
struct ScenarioResolvers {
  PythonControllerFactory python;
  /// The module file of a class `python` made; empty: a Python controller's provenance has a null
  /// module file and hash.
  PythonModuleLocator python_module;
  std::shared_ptr<const FmuResolver> fmu;
};

}  // namespace quadcosim::io
