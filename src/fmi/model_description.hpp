// modelDescription.xml of an FMU, as quadcosim reads (fmi/fmu.hpp, libxml2) and writes it
// (`quadcosim fmu export`): the parts a co-simulation master and slave need. FMI 2.0 and 3.0 name
// the same things differently (guid / instantiationToken, Real / Float64, ScalarVariable / typed
// elements); this struct holds them once.
#pragma once

#include <cstdint>
#include <optional>
#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

namespace quadcosim::fmi {

using ValueReference = std::uint32_t;

/// A refusal or a failed FMI call, with a message naming the FMU, the call or variable, and (for
/// a call) what the FMU logged.
class FmuError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

enum class FmiVersion { k2, k3 };
/// FMI 2 Real and FMI 3 Float64 are kReal; FMI 2 Integer and FMI 3 Int32 are kInteger; kOther is any
/// type quadcosim does not exchange (it may be present, it is never set or read).
enum class VariableType { kReal, kInteger, kBoolean, kString, kEnumeration, kOther };
enum class Causality { kParameter, kCalculatedParameter, kStructuralParameter, kInput, kOutput, kLocal, kIndependent };
enum class Variability { kConstant, kFixed, kTunable, kDiscrete, kContinuous };
enum class Initial { kUnset, kExact, kApprox, kCalculated };

std::string_view to_string(VariableType t);
std::string_view to_string(Causality c);
std::string_view to_string(Variability v);
std::string_view to_string(Initial i);

struct Variable {
  std::string name;
  ValueReference vr = 0;
  VariableType type = VariableType::kReal;
  Causality causality = Causality::kLocal;
  Variability variability = Variability::kContinuous;
  Initial initial = Initial::kUnset;
  std::optional<std::string> start;  ///< as written in the XML
  std::string unit;                  ///< "" when none is declared
  std::string description;
  std::optional<double> min, max;  ///< declared bounds (numbers only)
};

struct ModelDescription {
  FmiVersion version = FmiVersion::k2;
  std::string fmi_version;  ///< the attribute as written: "2.0", "3.0"
  std::string model_name;
  std::string description;
  std::string guid;  ///< FMI 2 guid, FMI 3 instantiationToken
  std::string generation_tool;
  // The CoSimulation element (required: an FMU without one is refused).
  std::string model_identifier;
  bool can_handle_variable_step = false;  ///< canHandleVariableCommunicationStepSize
  bool can_be_instantiated_only_once_per_process = false;
  // DefaultExperiment, when given.
  std::optional<double> start_time, stop_time, step_size;
  std::vector<Variable> variables;
  /// ModelStructure/Outputs: indices into `variables`.
  std::vector<std::size_t> outputs;

  /// The variable of that name, or nullptr.
  const Variable* find(std::string_view name) const;
};

/// Parses modelDescription.xml text; `source` names it in errors. Throws FmuError naming
/// the element or attribute that is missing or malformed.
ModelDescription parse_model_description(std::string_view xml, const std::string& source);

/// modelDescription.xml text for `md` in its FMI version (the export's writer).
std::string write_model_description(const ModelDescription& md);

}  // namespace quadcosim::fmi
