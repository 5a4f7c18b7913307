// How quadcosim's signals meet an FMU's variables (fmi/fmu_plant.hpp, fmi/fmu_controller.hpp): a
// scenario's `plant: {fmu: ...}` or `controller: {fmu: ...}` names, per signal, the FMU variables
// that carry it (`outputs: {p_W: [x, y, z]}`), or nothing, and then the names of
// fmi/quadrotor_variables.hpp are used. Every mapped variable is checked: it exists, is Real (FMI 3
// Float64), has the causality its side needs (what quadcosim sets: input; what it reads: output or
// local) and, when it declares a unit, the signal's unit. A refusal is a MappingError whose key
// names the scenario key under the section ("inputs.omega_cmd", "outputs.p_W", "parameters.mass").
#pragma once

#include <map>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "fmi/fmu.hpp"
#include "fmi/model_description.hpp"

namespace quadcosim::fmi {

/// What a scenario says about one FMU besides its path.
struct FmuMapping {
  /// Signal name ("omega_cmd", "p_W", ...) -> the FMU variables carrying its components, in order.
  std::map<std::string, std::vector<std::string>, std::less<>> inputs, outputs;
  /// FMU variable name -> value as written (a number, or true/false for a Boolean), set before
  /// initialisation after everything quadcosim sets itself.
  std::vector<std::pair<std::string, std::string>> parameters;
  /// Each instance runs in a child process of its own (fmi/isolated_instance.hpp): the FMU's crashes,
  /// exits and hangs end the run with a message instead of taking it down. false (the scenario's
  /// `in_process: true`): the FMU runs in quadcosim's process, which costs no round trip per step.
  bool isolated = true;
  /// How long an isolated instance's call may take once initialised (doStep and the gets and sets
  /// around it) before its process is killed and the call throws FmuError naming the limit; 0: no
  /// limit (Ctrl-C and SIGTERM still end a hung call). The scenario's `step_timeout_s` (default 10 s,
  /// as the lockstep `--timeout`). Instantiation and initialisation are not limited.
  double step_timeout_s = 10.0;
};

/// A mapping that does not fit the FMU. key(): the scenario key under the `plant:`/`controller:`
/// section ("fmu", "inputs.omega_cmd", "outputs.q_WB", "parameters.k").
class MappingError : public FmuError {
 public:
  MappingError(std::string key, const std::string& what) : FmuError(what), key_(std::move(key)) {}
  const std::string& key() const { return key_; }

 private:
  std::string key_;
};

/// One signal quadcosim exchanges with an FMU.
struct Signal {
  std::string_view name;                    ///< "p_W": the key in inputs/outputs
  std::span<const std::string_view> names;  ///< default FMU variable names, one per component
  std::string_view unit;                    ///< the unit a declared unit must be ("1": also none)
  bool required = false;                    ///< refused when absent
};

/// Which side of the FMU a signal is on.
enum class Side {
  kInput,   ///< quadcosim sets it: causality input
  kOutput,  ///< quadcosim reads it: causality output or local
};

/// The value references of one signal's components, empty when an optional signal is absent.
using SignalRefs = std::vector<ValueReference>;

/// Resolves `signal` on `side` of `md` from the scenario's `given` names (nullptr: none given, use
/// the defaults). A signal given explicitly must be there; an optional one absent by its default
/// names is empty; a required one absent throws. Throws MappingError naming `key_prefix` + signal.
SignalRefs resolve_signal(const ModelDescription& md, const std::string& fmu_name, const Signal& signal, Side side,
                          const std::vector<std::string>* given);

/// Refuses a key of `given` that is not one of `signals` (MappingError "inputs.<key>").
void check_signal_keys(const std::map<std::string, std::vector<std::string>, std::less<>>& given,
                       std::span<const Signal> signals, const std::string& section);

/// A parameter the scenario sets by FMU variable name, checked against the description.
struct ParameterSetting {
  const Variable* variable = nullptr;
  double number = 0.0;  ///< Real and Integer values; Boolean: 0 or 1
};

/// Checks `mapping.parameters` against `md` (the variable exists, is a parameter or an input that
/// may be set, of type Real, Integer or Boolean, and the value is one of that type); throws
/// MappingError "parameters.<name>".
std::vector<ParameterSetting> check_parameters(const ModelDescription& md, const std::string& fmu_name,
                                               const FmuMapping& mapping);

/// Sets one value of `v`'s type on `instance`.
void set_value(Instance& instance, const Variable& v, double number);

/// "FMU quadrotor.fmu (model 'Quadrotor', FMI 2.0)".
std::string describe_fmu(const Fmu& fmu);

/// The file name of the FMU, for messages ("quadrotor.fmu").
std::string fmu_name(const Fmu& fmu);

}  // namespace quadcosim::fmi
