// Scenario files (YAML): vehicle, controller parameters, rates, duration, initial state, a schedule of
// parameter changes, and the step figures to check. See docs/scenarios.md for every key.
#pragma once

#include <Eigen/Core>
#include <filesystem>
#include <functional>
#include <map>
#include <memory>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include "control/parameters.hpp"
#include "controllers/registry.hpp"
#include "fmi/fmu_mapping.hpp"
#include "io/scenario_resolvers.hpp"
#include "model/quadrotor.hpp"
#include "model/vehicle_params.hpp"
#include "sim/simulation.hpp"
#include "sim/swarm.hpp"
#include "trajectory/spec.hpp"
#include "trajectory/trajectory.hpp"

namespace YAML {
class Node;
}

namespace quadcosim::io {

/// Bad file content. what() names the file, the key path, the value and what was expected, e.g.
/// "scenarios/x.yaml: simulation.plant_rate_hz: got 'fast', expected a number > 0".
class ConfigError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

struct InitialState {
  Eigen::Vector3d p_W = Eigen::Vector3d::Zero();  ///< [m]
  double yaw_rad = 0.0;
  bool hover = false;  ///< rotors start at hover speed (airborne trimmed start) instead of stopped
};

/// The set a criterion belongs to (docs/scenarios.md, "Criteria: spec and paper"). `spec:` is a
/// specification: bounds any good controller of the vehicle must meet (e.g. overshoot at most 25 %).
/// `paper:` is the paper's controller's measured response: bands around its figures (e.g. overshoot
/// 15-21 %), which a better controller leaves. The old key `criteria:` is read as `spec:`.
enum class CriteriaSet { kSpec, kPaper };

/// What a run is judged against (`--judge`, the Python `judge=`): one criteria set, or none (figures
/// only: every figure is computed and written, no verdict is given).
enum class Judge { kSpec, kPaper, kNone };

/// "spec", "paper".
const char* to_string(CriteriaSet set);
/// "spec", "paper", "none".
const char* to_string(Judge judge);
/// "spec", "paper", "none": the values --judge takes, in this order.
const std::vector<std::string>& judge_names();
/// The Judge named `name` (one of judge_names()), or nothing for any other text.
std::optional<Judge> parse_judge(const std::string& name);
/// Whether `judge` judges the criteria of `set`.
constexpr bool judges(Judge judge, CriteriaSet set) {
  return (judge == Judge::kSpec && set == CriteriaSet::kSpec) || (judge == Judge::kPaper && set == CriteriaSet::kPaper);
}

/// A pass band on one figure; either bound may be absent.
struct Criterion {
  std::string figure;  ///< one of analysis::figure_names() (steps), of the hold, tracking or limits figures
  std::optional<double> min, max;
  CriteriaSet set = CriteriaSet::kSpec;
};

/// A step to analyse: the channel's setpoint changes at t_step_s.
struct StepSpec {
  std::string channel;  ///< x, y, z, roll, pitch or yaw
  double t_step_s = 0.0;
  /// Band of the settled verdict and of the settling time, as a fraction of the step
  /// (analysis.steps[].settling_band_pct / 100; 2 % unless set, e.g. wider where sensor noise exceeds it).
  double settling_band = 0.02;
  std::vector<Criterion> criteria;          ///< both sets, in file order (spec first, then paper)
  std::string reference_source;             ///< where the reference figures come from
  std::map<std::string, double> reference;  ///< published figures to compare with
};

/// A scenario's `swarm:` section: many vehicles of the same scenario on a grid (sim/swarm.hpp).
struct SwarmSpec {
  sim::SwarmLayout layout;
  int threads = 2;                   ///< in-process worker threads (1..64)
  std::vector<int> record_vehicles;  ///< vehicles whose full trajectory is written (default none)
};

/// Position hold (beyond the steps): from after_s on, how far the vehicle strays from its setpoint.
/// Figures: max_horizontal_error_m (max of the horizontal distance to (x_des, y_des)),
/// rms_horizontal_error_m, max_vertical_error_m (max |z - z_des|), all over t >= after_s.
struct HoldSpec {
  double after_s = 0.0;
  std::vector<Criterion> criteria;  ///< both sets (spec first, then paper)
};

/// "max_horizontal_error_m", "rms_horizontal_error_m", "max_vertical_error_m".
const std::vector<std::string>& hold_figure_names();

/// analysis.tracking: how closely the run follows its reference trajectory (analysis/tracking.hpp), judged
/// over t >= after_s. Present in a Scenario also without that key when the scenario has a `trajectory:`
/// (after_s 0, no criteria), so every tracking run reports its figures.
struct TrackingSpec {
  double after_s = 0.0;
  std::vector<Criterion> criteria;  ///< on analysis::tracking_figure_names(), both sets
  /// The controller's period [s] (simulation.controller_rate_hz): only samples at its steps are judged.
  double reference_period_s = 0.0;
};

/// analysis.limits: upper bounds on the run's saturation and control effort (io::SaturationResult).
/// Keys max_saturated_s, max_rotor_saturated_s (each rotor), max_tilt_saturated_s and
/// max_rms_u1_deviation_n become criteria {figure, max} on the figures saturated_s,
/// rotor1..4_saturated_s, tilt_saturated_s and rms_u1_deviation_n. The keys stand at the top of
/// analysis.limits (a specification, as before), or under its `spec:` and `paper:`.
struct LimitsSpec {
  std::vector<Criterion> criteria;  ///< both sets
};

/// A scenario's `plant: {fmu: ...}` or `controller: {fmu: ...}` (or the CLI's --fmu): the FMU and how
/// its variables map to quadcosim's signals (fmi/fmu_mapping.hpp; empty: the default names).
struct FmuSpec {
  std::string path;  ///< resolved against the scenario file's folder
  fmi::FmuMapping mapping;
};

struct Scenario {
  std::string path;  ///< file it was read from ("" for built-in defaults)
  std::string name;
  std::string description;
  model::VehicleParams vehicle;
  /// The controller, its parameters and the node's setpoints (the paper's controller by default), and
  /// the `trajectory:` to track (controller.trajectory; none for kind steps, the default).
  control::ControllerConfig controller =
      controllers::make_config(controllers::kDefaultControllerType, model::VehicleParams{});
  /// The `trajectory:` section's description, from which controller.trajectory was made (what an
  /// exported controller FMU carries); nothing without a trajectory.
  std::optional<trajectory::TrajectorySpec> trajectory_spec;
  sim::SimulationConfig simulation;
  InitialState initial;
  std::vector<sim::ScheduledParameter> schedule;
  std::vector<StepSpec> steps;
  std::optional<SwarmSpec> swarm;        ///< present when the file has a `swarm:` section
  std::optional<HoldSpec> hold;          ///< analysis.hold
  std::optional<LimitsSpec> limits;      ///< analysis.limits
  std::optional<TrackingSpec> tracking;  ///< analysis.tracking, or its defaults when a trajectory is tracked
  /// `plant: {fmu: ...}`: the FMU flown as the plant (simulation.plant.external is its factory).
  std::optional<FmuSpec> plant_fmu;
  /// `controller: {fmu: ...}`: the FMU flown as the controller (controller.controller is it).
  std::optional<FmuSpec> controller_fmu;
};

/// Whether the scenario has a criterion of `set` (in a step, the hold, the limits or the tracking).
bool has_criteria(const Scenario& scenario, CriteriaSet set);

/// Makes `sc` fly `spec` as its plant (`quadcosim plant --fmu`): loads the FMU, checks the mapping,
/// sets simulation.plant.external. Throws ConfigError naming `source` (the flag or file) and what
/// does not fit, also when the scenario uses what only the native plant has (wind, faults, drag).
void use_plant_fmu(Scenario& sc, const FmuSpec& spec, const std::string& source, const ScenarioResolvers& resolvers);

/// Makes `sc` fly `spec` as its controller (`quadcosim controller --fmu`), keeping the node's
/// settings (setpoints, safety) and the trajectory. Throws ConfigError naming `source`.
void use_controller_fmu(Scenario& sc, const FmuSpec& spec, const std::string& source,
                        const ScenarioResolvers& resolvers);

/// The plant state the scenario starts from (its `initial` section on its vehicle).
model::State initial_state(const Scenario& scenario);

/// Loads and validates a scenario; the FMUs and Python classes it names are made by `resolvers`
/// (io/scenario_resolvers.hpp), as in every function below that takes them. Throws ConfigError (file
/// unreadable, YAML syntax, unknown key, wrong type, value out of range, a rate that is not a whole
/// divisor, ...).
Scenario load_scenario(const std::string& path, const ScenarioResolvers& resolvers);

/// The same flown by `controller` when it is not empty (the CLI's --controller; see
/// set_controller_type for what it may name).
Scenario load_scenario(const std::string& path, const std::string& controller, const ScenarioResolvers& resolvers);

/// What `--controller` names: a registered type ("se3"), a class written in Python
/// ("python:MODULE:CLASS"), or a co-simulation FMU ("fmu:PATH", made absolute from the current
/// directory). Throws std::invalid_argument saying what was expected.
struct ControllerChoice {
  enum class Kind { kType, kPython, kFmu, kSitl } kind = Kind::kType;
  /// the type's name, MODULE:CLASS ("" for a bare "python"), the FMU's absolute path, or for
  /// "sitl:FIRMWARE[:BINARY]" the binary's absolute path ("": the scenario's or the environment's)
  std::string target;
  std::string firmware;  ///< "sitl:FIRMWARE[:BINARY]": the firmware (ardupilot)
};
ControllerChoice parse_controller_choice(const std::string& text);

/// What a command without a scenario file flies: the defaults (the paper's vehicle, named "defaults")
/// flown by `controller` (parse_controller_choice; "" keeps the paper's). A Python class or an FMU is
/// made as a scenario's controller section makes it. Throws as load_scenario and parse_controller_choice.
Scenario defaults_flown_by(const std::string& controller, const ScenarioResolvers& resolvers);

/// Makes a parsed scenario (a mapping) fly `controller` (parse_controller_choice; a bare "python"
/// leaves the class to the caller's controller.python), creating the section if needed. What is
/// flown (the node's mode, setpoints, safety) stays. The gains written directly under controller:
/// belong to the file's controller: a registered type's move into its own gains section (`paper:
/// {lqr: ...}`, still checked, not used); a Python class's or an FMU's (and its python, fmu,
/// inputs, outputs, parameters; step_timeout_s unless a Python class flies next) are dropped; a Python
/// class taking a registered type's place keeps the flat gains as its own. The gains section of the
/// type that flies now, when the file has one, applies. Throws std::invalid_argument as parse_controller_choice.
void set_controller_type(YAML::Node root, const std::string& controller);

/// The same from a parsed YAML document (`root` must be a mapping); errors name `source` as the file
/// and `path` is recorded as the scenario's path. A sweep sets keys in the parsed file and loads each
/// run's scenario with this, so a run's value is checked exactly as the same value written in the file.
/// `controller_vehicle`, when given, is the vehicle the controller is designed for instead of the
/// scenario's own (a sweep's runs fly a controller designed for the nominal vehicle).
Scenario load_scenario(const YAML::Node& root, const std::string& source, const ScenarioResolvers& resolvers,
                       const model::VehicleParams* controller_vehicle = nullptr);

/// Loads a vehicle file: the keys of a scenario's `vehicle:` section at top level. Throws ConfigError.
model::VehicleParams load_vehicle(const std::string& path);

/// Loads a controller parameter file: the keys of a scenario's `controller:` section, on top of the
/// defaults (whose vehicle knowledge comes from `vehicle`). Throws ConfigError.
control::ControllerConfig load_controller(const std::string& path, const model::VehicleParams& vehicle,
                                          const ScenarioResolvers& resolvers);

}  // namespace quadcosim::io
