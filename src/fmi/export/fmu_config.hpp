// What an exported FMU flies: its configuration, stored as JSON in the FMU's resources folder
// (resources/quadcosim.json) and read by the FMU binary when it is instantiated, and the FMI variables
// that configuration gives the FMU (describe(): what modelDescription.xml lists).
//
// One binary (the quadcosim_fmu library, fmi/export/CMakeLists.txt) serves both kinds; `kind` in the
// JSON says which it is, and the FMU's modelIdentifier names it: quadcosim_plant or
// quadcosim_controller (binaries/linux64/<modelIdentifier>.so, FMI 3: binaries/x86_64-linux/).
//
// `quadcosim fmu export` fills FmuConfig from a scenario: kind and fmi_version from the command,
// plant_period_ns, substeps and controller_divider from the scenario's timing, vehicle and initial
// from its vehicle and initial state, realism and realism_namespace from its realism section and
// namespace, controller_type, controller_parameters and setpoint from its controller section,
// trajectory from its trajectory section, stop_time_s from its duration, and guid from make_guid().
// This library reads no scenario file.
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "control/controller.hpp"
#include "control/controller_config.hpp"
#include "controllers/registry.hpp"
#include "fmi/model_description.hpp"
#include "model/quadrotor.hpp"
#include "model/vehicle_params.hpp"
#include "sim/realism.hpp"
#include "trajectory/spec.hpp"

namespace quadcosim::fmi {

enum class FmuKind { kPlant, kController };
std::string_view to_string(FmuKind kind);

/// The configuration file's name in the FMU's resources folder.
inline constexpr std::string_view kConfigFileName = "quadcosim.json";

/// "quadcosim_plant" / "quadcosim_controller": the CoSimulation modelIdentifier, and the name of the
/// shared library in binaries/<platform>/ (plus ".so").
std::string_view model_identifier(FmuKind kind);

struct FmuConfig {
  FmuKind kind = FmuKind::kPlant;
  FmiVersion fmi_version = FmiVersion::k2;
  /// FMI 2 guid / FMI 3 instantiationToken; instantiation with another one is refused. Empty: set it
  /// with make_guid() before writing the FMU.
  std::string guid;

  // Timing, as the scenario gives it (sim::SimulationConfig, sim::PlantOptions).
  std::int64_t plant_period_ns = 10'000'000;  ///< plant tick [ns]
  int substeps = 1;                           ///< RK4 steps per plant tick
  int controller_divider = 2;                 ///< controller period = divider * plant period
  std::optional<double> stop_time_s;          ///< DefaultExperiment stopTime [s], when known

  /// The vehicle: the plant's physics, the controller's knowledge of it. Every numeric parameter is also
  /// an FMU parameter `vehicle.<name>` (plant FMU).
  model::VehicleParams vehicle;
  /// The plant's initial state (its parameters `initial.<output>`); the controller FMU's sensor inputs
  /// start from the outputs this state gives.
  model::State initial;

  /// Plant FMU: wind, rotor faults and sensor noise as the scenario configured them (all off by
  /// default); the FMU's realism.* switches turn each part off or on again. `realism_namespace` names
  /// the noise streams (model::stream_seed) as the vehicle's namespace does in a quadcosim run.
  sim::RealismConfig realism;
  std::string realism_namespace = "/drone";

  /// Controller FMU: the registry type (controllers/registry.hpp) and the values of its parameters
  /// that differ from the type's defaults for `vehicle` (any subset, applied all at once).
  std::string controller_type{controllers::kDefaultControllerType};
  std::vector<control::Setting> controller_parameters;
  /// Controller FMU: the reference inputs' start values (and the mode: attitude or position).
  control::Setpoint setpoint;
  /// Controller FMU: the scenario's trajectory, flown in position mode from the FMU's own time (the
  /// setpoint is then unused); the Boolean parameter ref.external switches to the ref.* inputs.
  std::optional<trajectory::TrajectorySpec> trajectory;
};

/// The JSON text of `config` (numbers in shortest round-trip form: reading it back gives the same bits).
std::string to_json(const FmuConfig& config);
/// Parses what to_json wrote. `source` names the text in errors. Throws FmuError naming the key that
/// is missing, unknown or malformed.
FmuConfig config_from_json(std::string_view text, const std::string& source);
/// Reads `directory`/quadcosim.json. Throws FmuError.
FmuConfig read_config(const std::string& directory);

/// A GUID derived from everything else in `config` ("{8-4-4-4-12}" hex): equal configurations get
/// equal GUIDs, different ones (practically) never.
std::string make_guid(const FmuConfig& config);

/// The FMU's description: fmiVersion, modelName, guid, the CoSimulation element (modelIdentifier,
/// canHandleVariableCommunicationStepSize false: a step must be a whole number of periods),
/// DefaultExperiment (start 0, stopTime, stepSize one period) and the variables with their value
/// references, causality, variability, initial, start, unit, description and bounds. Value reference
/// 0 is `time` (causality independent); the others follow in the order below. N is the vehicle's
/// rotor count (4..8): rotors 5..N come last, after `period` (omega_cmd[5..N], then for the plant
/// omega[5..N] and initial.omega[5..N]), so that every variable of a quadrotor's FMU keeps its
/// value reference and a quadrotor's description is what it was before N could differ.
///
/// Plant FMU (period: the plant period):
///   inputs       omega_cmd[1..N] [rad/s], start initial.omega
///   outputs      p_W[1..3], v_W[1..3], q_WB[1..4] (w x y z), euler[1..3] (roll pitch yaw), w_B[1..3],
///                f_B[1..3] (specific force), omega[1..N] (rotor speeds reached)
///   parameters   (fixed: they take effect when initialisation ends) vehicle.<name> for every numeric
///                vehicle parameter, initial.<output> for p_W, v_W, q_WB, w_B, omega, the realism
///                switches realism.wind, realism.rotor_faults, realism.sensor_noise (Boolean) and
///                realism.seed (Integer)
/// Controller FMU (period: the controller period):
///   inputs       p_W, v_W, q_WB, w_B, f_B (the plant's outputs), ref.p_W, ref.v_W, ref.a_W, ref.j_W,
///                ref.yaw, ref.yaw_rate, ref.roll, ref.pitch (start: the setpoint, or the trajectory at
///                t = 0)
///   outputs      omega_cmd[1..N] [rad/s] (discrete)
///   parameters   (tunable) controller.<name> for every declared controller parameter (Real, or String
///                for a choice); with a trajectory, (fixed) ref.external (Boolean, start false: the
///                trajectory is the reference; true: the ref.* inputs are, in position mode)
/// Throws FmuError when the controller type is unknown or its parameters are refused, or the vehicle's
/// rotor count is not 4..8 or not that of initial.omega.
ModelDescription describe(const FmuConfig& config);

}  // namespace quadcosim::fmi
