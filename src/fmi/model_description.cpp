// modelDescription.xml of FMI 2.0 and 3.0 read with libxml2 into fmi::ModelDescription. The
// document is parsed from memory with no network, no DTD loading and no entity substitution; a
// document with a DOCTYPE is refused (modelDescription.xml has none, and entities are the way XML
// amplifies a small file into a large one). Every element and attribute the master needs is checked
// here, so that the loader and the instances can rely on what they get.
#include <fmt/format.h>
#include <libxml/parser.h>
#include <libxml/tree.h>
#include <libxml/xmlerror.h>

#include <algorithm>
#include <charconv>
#include <climits>
#include <limits>
#include <map>
#include <memory>
#include <mutex>

#include "fmi/model_description.hpp"

#include "fmi/unzip.hpp"

namespace quadcosim::fmi {

std::string_view to_string(VariableType t) {
  switch (t) {
    case VariableType::kReal: return "Real";
    case VariableType::kInteger: return "Integer";
    case VariableType::kBoolean: return "Boolean";
    case VariableType::kString: return "String";
    case VariableType::kEnumeration: return "Enumeration";
    case VariableType::kOther: return "other";
  }
  return "?";
}

std::string_view to_string(Causality c) {
  switch (c) {
    case Causality::kParameter: return "parameter";
    case Causality::kCalculatedParameter: return "calculatedParameter";
    case Causality::kStructuralParameter: return "structuralParameter";
    case Causality::kInput: return "input";
    case Causality::kOutput: return "output";
    case Causality::kLocal: return "local";
    case Causality::kIndependent: return "independent";
  }
  return "?";
}

std::string_view to_string(Variability v) {
  switch (v) {
    case Variability::kConstant: return "constant";
    case Variability::kFixed: return "fixed";
    case Variability::kTunable: return "tunable";
    case Variability::kDiscrete: return "discrete";
    case Variability::kContinuous: return "continuous";
  }
  return "?";
}

std::string_view to_string(Initial i) {
  switch (i) {
    case Initial::kUnset: return "unset";
    case Initial::kExact: return "exact";
    case Initial::kApprox: return "approx";
    case Initial::kCalculated: return "calculated";
  }
  return "?";
}

const Variable* ModelDescription::find(std::string_view name) const {
  for (const Variable& v : variables) {
    if (v.name == name) return &v;
  }
  return nullptr;
}

namespace {

struct DocDeleter {
  void operator()(xmlDoc* d) const { xmlFreeDoc(d); }
};
struct ContextDeleter {
  void operator()(xmlParserCtxt* c) const { xmlFreeParserCtxt(c); }
};

bool is_element(const xmlNode* n, const char* name) {
  return n != nullptr && n->type == XML_ELEMENT_NODE && xmlStrEqual(n->name, BAD_CAST name) != 0;
}

std::string_view element_name(const xmlNode* n) { return reinterpret_cast<const char*>(n->name); }

/// The first child element named `name`, or nullptr.
const xmlNode* child(const xmlNode* parent, const char* name) {
  for (const xmlNode* c = parent->children; c != nullptr; c = c->next) {
    if (is_element(c, name)) return c;
  }
  return nullptr;
}

std::string_view trim(std::string_view s) {
  const auto first = s.find_first_not_of(" \t\r\n");
  if (first == std::string_view::npos) return {};
  return s.substr(first, s.find_last_not_of(" \t\r\n") - first + 1);
}

/// Reads the attributes and children of one document; every error names `source_`.
class Reader {
 public:
  explicit Reader(const std::string& source) : source_(source) {}

  template <typename... Args>
  [[noreturn]] void fail(const xmlNode* at, fmt::format_string<Args...> format, Args&&... args) const {
    std::string message = fmt::format("{}: {}", source_, fmt::format(format, std::forward<Args>(args)...));
    if (at != nullptr && xmlGetLineNo(at) > 0) message += fmt::format(" (line {})", xmlGetLineNo(at));
    throw FmuError(message);
  }

  /// The attribute as written (entities are refused with the DOCTYPE, so it is literal text).
  static std::optional<std::string> attr(const xmlNode* n, const char* name) {
    xmlChar* value = xmlGetNoNsProp(n, BAD_CAST name);
    if (value == nullptr) return std::nullopt;
    std::string s(reinterpret_cast<const char*>(value));
    xmlFree(value);
    return s;
  }

  /// `what` names the element in errors: "ScalarVariable 'x'", "CoSimulation".
  std::string required(const xmlNode* n, const std::string& what, const char* name) const {
    auto value = attr(n, name);
    if (!value) fail(n, "{} has no {}", what, name);
    return *value;
  }

  std::optional<double> number(const xmlNode* n, const std::string& what, const char* name) const {
    const auto text = attr(n, name);
    if (!text) return std::nullopt;
    std::string_view s = trim(*text);
    if (!s.empty() && s.front() == '+') s.remove_prefix(1);
    double value = 0.0;
    // xs:double spells infinity INF; from_chars reads inf, INF, infinity and nan in any case.
    const auto [end, ec] = std::from_chars(s.data(), s.data() + s.size(), value);
    if (s.empty() || ec != std::errc() || end != s.data() + s.size()) {
      fail(n, "{}: {}=\"{}\" is not a number", what, name, *text);
    }
    return value;
  }

  bool boolean(const xmlNode* n, const std::string& what, const char* name, bool fallback) const {
    const auto text = attr(n, name);
    if (!text) return fallback;
    const std::string_view s = trim(*text);
    if (s == "true" || s == "1") return true;
    if (s == "false" || s == "0") return false;
    fail(n, "{}: {}=\"{}\" is not a boolean (true or false)", what, name, *text);
  }

  ValueReference value_reference(const xmlNode* n, const std::string& what) const {
    const std::string text = required(n, what, "valueReference");
    const std::string_view s = trim(text);
    unsigned long long value = 0;
    const auto [end, ec] = std::from_chars(s.data(), s.data() + s.size(), value);
    if (s.empty() || ec != std::errc() || end != s.data() + s.size() ||
        value > std::numeric_limits<ValueReference>::max()) {
      fail(n, "{}: valueReference=\"{}\" is not an unsigned 32-bit integer", what, text);
    }
    return static_cast<ValueReference>(value);
  }

  Causality causality(const xmlNode* n, const std::string& what) const {
    const auto text = attr(n, "causality");
    if (!text) return Causality::kLocal;
    for (auto c : {Causality::kParameter, Causality::kCalculatedParameter, Causality::kStructuralParameter,
                   Causality::kInput, Causality::kOutput, Causality::kLocal, Causality::kIndependent}) {
      if (*text == to_string(c)) return c;
    }
    fail(n,
         "{}: causality=\"{}\" is none of parameter, calculatedParameter, structuralParameter, input, output, "
         "local, independent",
         what, *text);
  }

  std::optional<Variability> variability(const xmlNode* n, const std::string& what) const {
    const auto text = attr(n, "variability");
    if (!text) return std::nullopt;
    for (auto v : {Variability::kConstant, Variability::kFixed, Variability::kTunable, Variability::kDiscrete,
                   Variability::kContinuous}) {
      if (*text == to_string(v)) return v;
    }
    fail(n, "{}: variability=\"{}\" is none of constant, fixed, tunable, discrete, continuous", what, *text);
  }

  Initial initial(const xmlNode* n, const std::string& what) const {
    const auto text = attr(n, "initial");
    if (!text) return Initial::kUnset;
    for (auto i : {Initial::kExact, Initial::kApprox, Initial::kCalculated}) {
      if (*text == to_string(i)) return i;
    }
    fail(n, "{}: initial=\"{}\" is none of exact, approx, calculated", what, *text);
  }

  const std::string& source() const { return source_; }

 private:
  const std::string& source_;
};

/// Units of the declared types (TypeDefinitions), by type name: FMI 2 SimpleType/Real, FMI 3
/// Float64Type and the other typed definitions.
std::map<std::string, std::string> declared_units(const xmlNode* root, FmiVersion version) {
  std::map<std::string, std::string> units;
  const xmlNode* defs = child(root, "TypeDefinitions");
  if (defs == nullptr) return units;
  for (const xmlNode* t = defs->children; t != nullptr; t = t->next) {
    if (t->type != XML_ELEMENT_NODE) continue;
    const auto name = Reader::attr(t, "name");
    if (!name) continue;
    const xmlNode* carrier = t;  // FMI 3: the unit is on the Float64Type element itself
    if (version == FmiVersion::k2) carrier = child(t, "Real");
    if (carrier == nullptr) continue;
    if (auto unit = Reader::attr(carrier, "unit")) units.emplace(*name, *unit);
  }
  return units;
}

/// The attributes of a variable common to FMI 2's ScalarVariable and its type child (`typed`) and to
/// FMI 3's typed element (both nodes the same).
void read_value_attributes(const Reader& r, const xmlNode* typed, const std::string& what,
                           const std::map<std::string, std::string>& units, Variable& v) {
  v.start = Reader::attr(typed, "start");
  // FMI 3 writes a String's start value as a child: <String ...><Start value="..."/></String>.
  if (!v.start && v.type == VariableType::kString) {
    if (const xmlNode* start = child(typed, "Start")) v.start = Reader::attr(start, "value");
  }
  if (auto unit = Reader::attr(typed, "unit")) {
    v.unit = *unit;
  } else if (auto declared = Reader::attr(typed, "declaredType")) {
    if (auto it = units.find(*declared); it != units.end()) v.unit = it->second;
  }
  if (v.type != VariableType::kString && v.type != VariableType::kBoolean) {
    v.min = r.number(typed, what, "min");
    v.max = r.number(typed, what, "max");
  }
}

void read_fmi2_variables(const Reader& r, const xmlNode* root, ModelDescription& md) {
  const auto units = declared_units(root, FmiVersion::k2);
  const xmlNode* list = child(root, "ModelVariables");
  if (list == nullptr) return;
  for (const xmlNode* n = list->children; n != nullptr; n = n->next) {
    if (n->type != XML_ELEMENT_NODE) continue;
    if (!is_element(n, "ScalarVariable")) {
      r.fail(n, "ModelVariables holds a <{}>: FMI 2.0 lists ScalarVariable elements only", element_name(n));
    }
    Variable v;
    v.name = r.required(n, fmt::format("ScalarVariable number {}", md.variables.size() + 1), "name");
    const std::string what = fmt::format("ScalarVariable '{}'", v.name);
    v.vr = r.value_reference(n, what);
    v.description = Reader::attr(n, "description").value_or("");
    v.causality = r.causality(n, what);
    v.initial = r.initial(n, what);
    const xmlNode* typed = nullptr;
    for (const xmlNode* c = n->children; c != nullptr && typed == nullptr; c = c->next) {
      if (c->type == XML_ELEMENT_NODE && !is_element(c, "Annotations")) typed = c;
    }
    if (typed == nullptr) r.fail(n, "{} has no type element (Real, Integer, Boolean, String or Enumeration)", what);
    if (is_element(typed, "Real")) {
      v.type = VariableType::kReal;
    } else if (is_element(typed, "Integer")) {
      v.type = VariableType::kInteger;
    } else if (is_element(typed, "Boolean")) {
      v.type = VariableType::kBoolean;
    } else if (is_element(typed, "String")) {
      v.type = VariableType::kString;
    } else if (is_element(typed, "Enumeration")) {
      v.type = VariableType::kEnumeration;
    } else {
      r.fail(typed, "{} has a <{}>, none of Real, Integer, Boolean, String, Enumeration", what, element_name(typed));
    }
    // FMI 2 defaults to continuous, which only a Real can be.
    v.variability = r.variability(n, what).value_or(v.type == VariableType::kReal ? Variability::kContinuous
                                                                                  : Variability::kDiscrete);
    read_value_attributes(r, typed, what, units, v);
    md.variables.push_back(std::move(v));
  }
}

void read_fmi3_variables(const Reader& r, const xmlNode* root, ModelDescription& md) {
  const auto units = declared_units(root, FmiVersion::k3);
  const xmlNode* list = child(root, "ModelVariables");
  if (list == nullptr) return;
  static const std::map<std::string_view, VariableType> kTypes = {{"Float64", VariableType::kReal},
                                                                  {"Int32", VariableType::kInteger},
                                                                  {"Boolean", VariableType::kBoolean},
                                                                  {"String", VariableType::kString},
                                                                  {"Enumeration", VariableType::kEnumeration},
                                                                  {"Float32", VariableType::kOther},
                                                                  {"Int8", VariableType::kOther},
                                                                  {"UInt8", VariableType::kOther},
                                                                  {"Int16", VariableType::kOther},
                                                                  {"UInt16", VariableType::kOther},
                                                                  {"UInt32", VariableType::kOther},
                                                                  {"Int64", VariableType::kOther},
                                                                  {"UInt64", VariableType::kOther},
                                                                  {"Binary", VariableType::kOther},
                                                                  {"Clock", VariableType::kOther}};
  for (const xmlNode* n = list->children; n != nullptr; n = n->next) {
    if (n->type != XML_ELEMENT_NODE) continue;
    const auto type = kTypes.find(element_name(n));
    if (type == kTypes.end()) {
      r.fail(n, "ModelVariables holds a <{}>, which is no FMI 3.0 variable type", element_name(n));
    }
    Variable v;
    v.type = type->second;
    v.name = r.required(n, fmt::format("{} number {}", element_name(n), md.variables.size() + 1), "name");
    const std::string what = fmt::format("{} '{}'", element_name(n), v.name);
    v.vr = r.value_reference(n, what);
    v.description = Reader::attr(n, "description").value_or("");
    v.causality = r.causality(n, what);
    v.initial = r.initial(n, what);
    const bool is_float = type->first == "Float64" || type->first == "Float32";
    v.variability = r.variability(n, what).value_or(is_float ? Variability::kContinuous : Variability::kDiscrete);
    // An array (Dimension children) is not a scalar the master can exchange.
    if (child(n, "Dimension") != nullptr) v.type = VariableType::kOther;
    if (v.type != VariableType::kOther) read_value_attributes(r, n, what, units, v);
    md.variables.push_back(std::move(v));
  }
}

void read_outputs(const Reader& r, const xmlNode* root, ModelDescription& md) {
  const xmlNode* structure = child(root, "ModelStructure");
  if (structure == nullptr) return;
  if (md.version == FmiVersion::k2) {
    const xmlNode* outputs = child(structure, "Outputs");
    if (outputs == nullptr) return;
    for (const xmlNode* u = outputs->children; u != nullptr; u = u->next) {
      if (!is_element(u, "Unknown")) continue;
      const std::string text = r.required(u, "ModelStructure/Outputs/Unknown", "index");
      const std::string_view s = trim(text);
      std::size_t index = 0;
      const auto [end, ec] = std::from_chars(s.data(), s.data() + s.size(), index);
      if (s.empty() || ec != std::errc() || end != s.data() + s.size() || index < 1 || index > md.variables.size()) {
        r.fail(u, "ModelStructure/Outputs/Unknown: index=\"{}\" is no variable (1 to {})", text, md.variables.size());
      }
      md.outputs.push_back(index - 1);
    }
    return;
  }
  for (const xmlNode* o = structure->children; o != nullptr; o = o->next) {
    if (!is_element(o, "Output")) continue;
    const ValueReference vr = r.value_reference(o, "ModelStructure/Output");
    const auto it =
        std::find_if(md.variables.begin(), md.variables.end(), [vr](const Variable& v) { return v.vr == vr; });
    if (it == md.variables.end()) r.fail(o, "ModelStructure/Output: valueReference {} is no variable's", vr);
    md.outputs.push_back(static_cast<std::size_t>(it - md.variables.begin()));
  }
}

}  // namespace

ModelDescription parse_model_description(std::string_view xml, const std::string& source) {
  static std::once_flag init;
  std::call_once(init, [] { xmlInitParser(); });  // the parser's globals, once, before threads use it
  if (xml.size() > static_cast<std::size_t>(INT_MAX)) {
    throw FmuError(fmt::format("{}: {} bytes is too large for a model description", source, xml.size()));
  }
  std::unique_ptr<xmlParserCtxt, ContextDeleter> context(xmlNewParserCtxt());
  if (!context) throw FmuError(fmt::format("{}: cannot make an XML parser (out of memory)", source));
  std::unique_ptr<xmlDoc, DocDeleter> doc(xmlCtxtReadMemory(context.get(), xml.data(), static_cast<int>(xml.size()),
                                                            "modelDescription.xml", nullptr,
                                                            XML_PARSE_NONET | XML_PARSE_NOERROR | XML_PARSE_NOWARNING));
  if (!doc || context->wellFormed == 0) {
    const xmlError* e = xmlCtxtGetLastError(context.get());
    std::string what = e != nullptr && e->message != nullptr ? std::string(trim(e->message)) : "unknown error";
    throw FmuError(fmt::format("{}: not well-formed XML{}: {}", source,
                               e != nullptr && e->line > 0 ? fmt::format(" at line {}", e->line) : "", what));
  }
  const Reader r(source);
  if (doc->intSubset != nullptr || doc->extSubset != nullptr) {
    r.fail(nullptr, "has a DOCTYPE declaration, which a model description does not have (entities are refused)");
  }
  const xmlNode* root = xmlDocGetRootElement(doc.get());
  if (!is_element(root, "fmiModelDescription")) {
    r.fail(root, "the root element is <{}>, not <fmiModelDescription>", root != nullptr ? element_name(root) : "");
  }

  ModelDescription md;
  md.fmi_version = r.required(root, "fmiModelDescription", "fmiVersion");
  if (md.fmi_version.starts_with("2.")) {
    md.version = FmiVersion::k2;
  } else if (md.fmi_version.starts_with("3.")) {
    md.version = FmiVersion::k3;
  } else {
    r.fail(root, "fmiVersion=\"{}\" is not supported: quadcosim masters FMI 2.0 and 3.0", md.fmi_version);
  }
  const bool v2 = md.version == FmiVersion::k2;
  if (const xmlNode* list = child(root, "ModelVariables"); list != nullptr && fmu_limits().enabled) {
    std::uint64_t n = 0;
    for (const xmlNode* c = list->children; c != nullptr; c = c->next) n += c->type == XML_ELEMENT_NODE ? 1 : 0;
    if (n > fmu_limits().variables) {
      r.fail(list, "ModelVariables lists {} variables, more than the {} an FMU may have ({})", n,
             fmu_limits().variables, limit_hint("fmu_variables"));
    }
  }
  md.model_name = r.required(root, "fmiModelDescription", "modelName");
  md.guid = r.required(root, "fmiModelDescription", v2 ? "guid" : "instantiationToken");
  md.description = Reader::attr(root, "description").value_or("");
  md.generation_tool = Reader::attr(root, "generationTool").value_or("");

  const xmlNode* cs = child(root, "CoSimulation");
  if (cs == nullptr) {
    r.fail(root, "model '{}' has no CoSimulation element: quadcosim masters co-simulation FMUs only{}", md.model_name,
           child(root, "ModelExchange") != nullptr ? " (this one is for model exchange)" : "");
  }
  md.model_identifier = r.required(cs, "CoSimulation", "modelIdentifier");
  // The identifier names the binary (binaries/<platform>/<modelIdentifier>.so): a C identifier, so
  // no path can be smuggled in through it.
  const bool c_identifier =
      !md.model_identifier.empty() && !(md.model_identifier[0] >= '0' && md.model_identifier[0] <= '9') &&
      std::all_of(md.model_identifier.begin(), md.model_identifier.end(), [](char ch) {
        return (ch >= 'a' && ch <= 'z') || (ch >= 'A' && ch <= 'Z') || (ch >= '0' && ch <= '9') || ch == '_';
      });
  if (!c_identifier) r.fail(cs, "CoSimulation: modelIdentifier=\"{}\" is not a C identifier", md.model_identifier);
  md.can_handle_variable_step = r.boolean(cs, "CoSimulation", "canHandleVariableCommunicationStepSize", false);
  md.can_be_instantiated_only_once_per_process =
      r.boolean(cs, "CoSimulation", "canBeInstantiatedOnlyOncePerProcess", false);
  md.can_get_and_set_fmu_state = r.boolean(
      cs, "CoSimulation", md.version == FmiVersion::k3 ? "canGetAndSetFMUState" : "canGetAndSetFMUstate", false);

  if (const xmlNode* experiment = child(root, "DefaultExperiment")) {
    md.start_time = r.number(experiment, "DefaultExperiment", "startTime");
    md.stop_time = r.number(experiment, "DefaultExperiment", "stopTime");
    md.step_size = r.number(experiment, "DefaultExperiment", "stepSize");
  }

  if (v2) {
    read_fmi2_variables(r, root, md);
  } else {
    read_fmi3_variables(r, root, md);
  }
  // Names are unique (the standard says so, and the master maps by name).
  std::map<std::string_view, std::size_t> seen;
  for (std::size_t i = 0; i < md.variables.size(); ++i) {
    if (!seen.emplace(md.variables[i].name, i).second) {
      r.fail(nullptr, "two variables are named '{}' (numbers {} and {})", md.variables[i].name,
             seen[md.variables[i].name] + 1, i + 1);
    }
  }
  read_outputs(r, root, md);
  return md;
}

}  // namespace quadcosim::fmi
