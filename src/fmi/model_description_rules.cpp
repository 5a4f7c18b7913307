// fmi/model_description_rules.hpp: a model description checked against the rules of the FMI standard.
#include "fmi/model_description_rules.hpp"

#include <libxml/xmlstring.h>

#include <algorithm>
#include <cctype>
#include <charconv>
#include <optional>
#include <set>
#include <string_view>
#include <system_error>

namespace quadcosim::fmi {

namespace {

// ---- Units ----------------------------------------------------------------------------------------

BaseUnit base(std::initializer_list<std::pair<int, int>> exponents) {
  BaseUnit u;
  for (const auto& [index, e] : exponents) u.exponent[static_cast<std::size_t>(index)] = e;
  return u;
}

/// The unit symbols a quadcosim unit is written with, as base units.
const std::map<std::string_view, BaseUnit>& symbols() {
  enum { kg, m, s, A, K, mol, cd, rad };
  static const std::map<std::string_view, BaseUnit> table = {
      {"kg", base({{kg, 1}})},
      {"m", base({{m, 1}})},
      {"s", base({{s, 1}})},
      {"A", base({{A, 1}})},
      {"K", base({{K, 1}})},
      {"mol", base({{mol, 1}})},
      {"cd", base({{cd, 1}})},
      {"rad", base({{rad, 1}})},
      {"N", base({{kg, 1}, {m, 1}, {s, -2}})},
      {"J", base({{kg, 1}, {m, 2}, {s, -2}})},
      {"W", base({{kg, 1}, {m, 2}, {s, -3}})},
      {"Pa", base({{kg, 1}, {m, -1}, {s, -2}})},
      {"T", base({{kg, 1}, {s, -2}, {A, -1}})},
      {"deg",
       [] {
         BaseUnit u = base({{rad, 1}});
         u.factor = std::numbers::pi / 180.0;
         return u;
       }()},
      {"Hz", base({{s, -1}})},
  };
  return table;
}

/// Reads a unit as quadcosim writes them: factors separated by spaces, "/" dividing by the product
/// that follows it (to the end or the closing parenthesis), exponents as "^2", "^-1" or trailing
/// digits ("m/s2"), parentheses, and "1" for a dimensionless numerator: "N m/(rad/s)^2",
/// "N/((m/s) (rad/s))", "1/(N m)^2", "m/s^2". Returns nullopt for anything else.
class UnitParser {
 public:
  explicit UnitParser(std::string_view text) : text_(text) {}

  std::optional<BaseUnit> parse() {
    std::optional<BaseUnit> u = quotient();
    skip_spaces();
    if (!u || pos_ != text_.size()) return std::nullopt;
    return u;
  }

 private:
  std::optional<BaseUnit> quotient() {
    std::optional<BaseUnit> num = product();
    if (!num) return std::nullopt;
    skip_spaces();
    if (peek() == '/') {
      ++pos_;
      std::optional<BaseUnit> den = product();
      if (!den) return std::nullopt;
      *num *= den->power(-1);
    }
    return num;
  }

  std::optional<BaseUnit> product() {
    std::optional<BaseUnit> u = factor();
    if (!u) return std::nullopt;
    for (;;) {
      skip_spaces();
      const char c = peek();
      if (c == '\0' || c == '/' || c == ')') return u;
      std::optional<BaseUnit> f = factor();
      if (!f) return std::nullopt;
      *u *= *f;
    }
  }

  std::optional<BaseUnit> factor() {
    skip_spaces();
    std::optional<BaseUnit> u;
    bool symbol = false;
    if (peek() == '(') {
      ++pos_;
      u = quotient();
      skip_spaces();
      if (!u || peek() != ')') return std::nullopt;
      ++pos_;
    } else if (peek() == '1') {
      ++pos_;
      u = BaseUnit{};
    } else {
      const std::size_t start = pos_;
      while (pos_ < text_.size() && std::isalpha(static_cast<unsigned char>(text_[pos_]))) ++pos_;
      const auto it = symbols().find(text_.substr(start, pos_ - start));
      if (it == symbols().end()) return std::nullopt;
      u = it->second;
      symbol = true;
    }
    // "^2", "^-1"; after a symbol also bare digits ("s2").
    const bool caret = peek() == '^';
    if (caret) ++pos_;
    if (caret || (symbol && std::isdigit(static_cast<unsigned char>(peek())))) {
      const std::optional<int> n = integer();
      if (!n) return std::nullopt;
      return u->power(*n);
    }
    return u;
  }

  std::optional<int> integer() {
    int n = 0;
    const char* first = text_.data() + pos_;
    const auto [end, ec] = std::from_chars(first, text_.data() + text_.size(), n);
    if (ec != std::errc{} || end == first) return std::nullopt;
    pos_ += static_cast<std::size_t>(end - first);
    return n;
  }

  char peek() const { return pos_ < text_.size() ? text_[pos_] : '\0'; }
  void skip_spaces() {
    while (peek() == ' ') ++pos_;
  }

  std::string_view text_;
  std::size_t pos_ = 0;
};

// ---- Names ----------------------------------------------------------------------------------------

/// True when `name` follows FMI's "structured" naming convention as quadcosim uses it: identifiers
/// joined by ".", each with an optional array subscript of positive integers ("p_W[1]",
/// "vehicle.aero.linear_drag_N_s_m.x", "a[1,2].b"). Quoted names and der(...) are not used here.
bool structured_name(std::string_view name) {
  std::size_t i = 0;
  const auto at = [&] { return i < name.size() ? name[i] : '\0'; };
  for (;;) {
    if (!(std::isalpha(static_cast<unsigned char>(at())) || at() == '_')) return false;
    while (std::isalnum(static_cast<unsigned char>(at())) || at() == '_') ++i;
    if (at() == '[') {
      do {
        ++i;
        if (!std::isdigit(static_cast<unsigned char>(at())) || at() == '0') return false;
        while (std::isdigit(static_cast<unsigned char>(at()))) ++i;
      } while (at() == ',');
      if (at() != ']') return false;
      ++i;
    }
    if (i == name.size()) return true;
    if (at() != '.') return false;
    ++i;
  }
}

// ---- What the standard allows ---------------------------------------------------------------------

/// The `initial` values the standard allows for a causality and variability (FMI 2.0 section 2.2.7,
/// FMI 3.0 table "Definition of initial"), the first being the default; empty when the combination
/// itself is not allowed, {kUnset} when `initial` must not be given.
std::vector<Initial> allowed_initial(Causality c, Variability v, FmiVersion version) {
  using enum Initial;
  const bool parameter_like = v == Variability::kFixed || v == Variability::kTunable;
  const bool changing = v == Variability::kDiscrete || v == Variability::kContinuous;
  switch (c) {
    case Causality::kParameter:
    case Causality::kStructuralParameter:
      if (parameter_like) return {kExact};
      return {};
    case Causality::kCalculatedParameter:
      if (parameter_like) return {kCalculated, kApprox};
      return {};
    case Causality::kInput:
      if (!changing) return {};
      // FMI 2 does not let an input say `initial` (its start value acts as exact: accepted, not
      // written); FMI 3 allows exact, its default.
      return version == FmiVersion::k2 ? std::vector<Initial>{kUnset, kExact} : std::vector<Initial>{kExact};
    case Causality::kOutput:
      if (v == Variability::kConstant) return {kExact};
      if (changing) return {kCalculated, kExact, kApprox};
      return {};
    case Causality::kLocal:
      if (v == Variability::kConstant) return {kExact};
      if (parameter_like) return {kCalculated, kApprox};
      return {kCalculated, kExact, kApprox};
    case Causality::kIndependent:
      if (v == Variability::kContinuous) return {kUnset};
      return {};
  }
  return {};
}

/// Refuses text that would make the XML malformed: invalid UTF-8, or control characters XML 1.0
/// does not allow (all below 0x20 but tab, line feed and carriage return).
void check_text(std::string_view text, std::string_view what) {
  for (const char ch : text) {
    const auto c = static_cast<unsigned char>(ch);
    if (c < 0x20 && c != '\t' && c != '\n' && c != '\r')
      throw FmuError("modelDescription.xml: " + std::string(what) + " holds control character " + std::to_string(c) +
                     ", which XML cannot carry");
  }
  const std::string copy(text);
  if (!copy.empty() && xmlCheckUTF8(reinterpret_cast<const xmlChar*>(copy.c_str())) == 0)
    throw FmuError("modelDescription.xml: " + std::string(what) + " is not valid UTF-8");
}

}  // namespace

Checked check_model_description(const ModelDescription& md) {
  const bool v3 = md.version == FmiVersion::k3;
  const auto fail = [](const std::string& what) { throw FmuError("modelDescription.xml: " + what); };
  if (md.model_name.empty()) fail("modelName is empty");
  if (md.guid.empty()) fail(v3 ? "instantiationToken is empty" : "guid is empty");
  if (md.model_identifier.empty()) fail("CoSimulation modelIdentifier is empty");
  // The identifier names the binary and (FMI 2 source FMUs) prefixes C functions: a C identifier.
  if (!structured_name(md.model_identifier) || md.model_identifier.find_first_of(".[") != std::string::npos)
    fail("CoSimulation modelIdentifier '" + md.model_identifier + "' is not a C identifier");
  check_text(md.model_name, "modelName");
  check_text(md.description, "description");
  check_text(md.guid, "guid");
  check_text(md.generation_tool, "generationTool");

  Checked out;
  std::set<std::string_view> names;
  std::map<std::pair<int, ValueReference>, const Variable*> vrs;  // FMI 2: unique per type; FMI 3: overall
  int independent = 0;
  for (const Variable& var : md.variables) {
    const std::string who = "variable '" + var.name + "'";
    if (var.name.empty()) fail("a variable has an empty name");
    check_text(var.name, "a variable's name");
    check_text(var.description, who + ": description");
    if (!names.insert(var.name).second) fail(who + " is declared twice");
    out.structured = out.structured && structured_name(var.name);

    if (var.type == VariableType::kEnumeration || var.type == VariableType::kOther)
      fail(who + ": only Real/Float64, Integer/Int32, Boolean and String variables are written");
    const int type_key = v3 ? 0 : static_cast<int>(var.type);
    if (const auto [it, fresh] = vrs.emplace(std::pair{type_key, var.vr}, &var); !fresh)
      fail(who + ": valueReference " + std::to_string(var.vr) + " is also that of '" + it->second->name + "'");

    if (var.causality == Causality::kStructuralParameter && !v3)
      fail(who + ": causality structuralParameter is FMI 3 only");
    if (var.causality == Causality::kIndependent) {
      ++independent;
      if (var.type != VariableType::kReal) fail(who + ": the independent variable must be a Real/Float64");
    }
    if (var.variability == Variability::kContinuous && var.type != VariableType::kReal)
      fail(who + ": only a Real/Float64 variable can be continuous");
    const std::vector<Initial> allowed = allowed_initial(var.causality, var.variability, md.version);
    if (allowed.empty())
      fail(who + ": causality " + std::string(to_string(var.causality)) + " with variability " +
           std::string(to_string(var.variability)) + " is not allowed");
    Initial initial = var.initial;
    if (initial == Initial::kUnset) initial = allowed.front();
    if (std::find(allowed.begin(), allowed.end(), initial) == allowed.end())
      fail(who + ": initial=" + std::string(to_string(initial)) + " is not allowed with causality " +
           std::string(to_string(var.causality)) + " and variability " + std::string(to_string(var.variability)));
    // Written as given, unless the standard lets this variable have no `initial` at all.
    out.initial.push_back(allowed.front() == Initial::kUnset ? Initial::kUnset : var.initial);
    out.effective.push_back(allowed.front() == Initial::kUnset ? Initial::kUnset : initial);

    const bool needs_start = initial == Initial::kExact || initial == Initial::kApprox ||
                             var.causality == Causality::kParameter || var.causality == Causality::kInput ||
                             var.variability == Variability::kConstant;
    const bool no_start = initial == Initial::kCalculated || var.causality == Causality::kIndependent;
    if (needs_start && !var.start) fail(who + ": a start value is required");
    if (no_start && var.start)
      fail(who + ": a start value is not allowed (initial=calculated or causality independent)");
    if (var.start) check_text(*var.start, who + ": start");

    if (!var.unit.empty()) {
      if (var.type != VariableType::kReal) fail(who + ": unit '" + var.unit + "' on a variable that is not Real");
      check_text(var.unit, who + ": unit");
      if (!out.base_units.contains(var.unit)) {
        const std::optional<BaseUnit> u = UnitParser(var.unit).parse();
        if (!u) fail(who + ": unit '" + var.unit + "' is not made of known SI symbols");
        out.base_units.emplace(var.unit, *u);
        out.units.push_back(var.unit);
      }
    }
    if ((var.min || var.max) && var.type != VariableType::kReal && var.type != VariableType::kInteger)
      fail(who + ": min/max on a variable that is not a number");
    if ((var.min && std::isnan(*var.min)) || (var.max && std::isnan(*var.max))) fail(who + ": min or max is NaN");
    if (var.min && var.max && *var.min > *var.max) fail(who + ": min > max");
  }
  if (v3 && independent != 1)
    fail("FMI 3 needs exactly one variable with causality independent (time), found " + std::to_string(independent));
  if (independent > 1) fail("more than one variable has causality independent");

  std::set<std::size_t> listed;
  for (const std::size_t i : md.outputs) {
    if (i >= md.variables.size()) fail("ModelStructure lists output " + std::to_string(i) + ", not a variable");
    if (md.variables[i].causality != Causality::kOutput)
      fail("ModelStructure lists '" + md.variables[i].name + "' as an output; its causality is " +
           std::string(to_string(md.variables[i].causality)));
    if (!listed.insert(i).second) fail("ModelStructure lists output '" + md.variables[i].name + "' twice");
  }
  for (std::size_t i = 0; i < md.variables.size(); ++i) {
    if (md.variables[i].causality == Causality::kOutput && !listed.contains(i))
      fail("output '" + md.variables[i].name + "' is missing from ModelStructure");
  }
  return out;
}

}  // namespace quadcosim::fmi
