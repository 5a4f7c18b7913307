#include "fmi/fmu_mapping.hpp"

#include <fmt/format.h>

#include <cmath>
#include <cstdint>
#include <filesystem>

#include "util/did_you_mean.hpp"

namespace quadcosim::fmi {

namespace {

std::string list(const std::vector<std::string>& names) {
  std::string out;
  for (const auto& n : names) out += (out.empty() ? "" : ", ") + n;
  return "[" + out + "]";
}

bool readable(Causality c) { return c == Causality::kOutput || c == Causality::kLocal; }

}  // namespace

std::string fmu_name(const Fmu& fmu) { return std::filesystem::path(fmu.path()).filename().string(); }

std::string describe_fmu(const Fmu& fmu) {
  const ModelDescription& md = fmu.description();
  return fmt::format("FMU {} (model '{}', FMI {})", fmu_name(fmu), md.model_name, md.fmi_version);
}

SignalRefs resolve_signal(const ModelDescription& md, const std::string& fmu, const Signal& signal, Side side,
                          const std::vector<std::string>* given) {
  const std::string key = std::string(side == Side::kInput ? "inputs." : "outputs.") + std::string(signal.name);
  std::vector<std::string> names;
  if (given) {
    names = *given;
    if (names.size() != signal.names.size()) {
      throw MappingError(key, fmt::format("got {} names {}, expected {} (one FMU variable per component)", names.size(),
                                          list(names), signal.names.size()));
    }
  } else {
    for (std::string_view n : signal.names) names.emplace_back(n);
    // Absent by the default names: an optional signal takes its default value.
    bool any = false, all = true;
    for (const auto& n : names) {
      const bool has = md.find(n) != nullptr;
      any = any || has;
      all = all && has;
    }
    if (!any && !signal.required) return {};
    if (!all) {
      std::string missing;
      for (const auto& n : names) {
        if (!md.find(n)) missing += (missing.empty() ? "'" : ", '") + n + "'";
      }
      throw MappingError(key, fmt::format("{} has no variable {} (the default name{}); name the FMU's variables, "
                                          "e.g. {}: {{{}: [...]}}",
                                          fmu, missing, names.size() > 1 ? "s" : "",
                                          side == Side::kInput ? "inputs" : "outputs", signal.name));
    }
  }
  SignalRefs refs;
  for (const auto& n : names) {
    const Variable* v = md.find(n);
    if (!v) throw MappingError(key, fmt::format("{} has no variable '{}'", fmu, n));
    if (v->type != VariableType::kReal) {
      throw MappingError(
          key, fmt::format("{}: variable '{}' is {}, expected Real (FMI 3: Float64)", fmu, n, to_string(v->type)));
    }
    if (side == Side::kInput && v->causality != Causality::kInput) {
      throw MappingError(
          key, fmt::format("{}: variable '{}' has causality {}, expected input", fmu, n, to_string(v->causality)));
    }
    if (side == Side::kOutput && !readable(v->causality)) {
      throw MappingError(key, fmt::format("{}: variable '{}' has causality {}, expected output or local", fmu, n,
                                          to_string(v->causality)));
    }
    const bool unit_ok = v->unit.empty() || v->unit == signal.unit;
    if (!unit_ok) {
      throw MappingError(key,
                         fmt::format("{}: variable '{}' has unit '{}', expected '{}'", fmu, n, v->unit, signal.unit));
    }
    refs.push_back(v->vr);
  }
  return refs;
}

void check_signal_keys(const std::map<std::string, std::vector<std::string>, std::less<>>& given,
                       std::span<const Signal> signals, const std::string& section) {
  for (const auto& [name, names] : given) {
    bool known = false;
    std::string expected;
    std::vector<std::string> signal_names;
    for (const Signal& s : signals) {
      known = known || s.name == name;
      expected += (expected.empty() ? "" : ", ") + std::string(s.name);
      signal_names.emplace_back(s.name);
    }
    if (!known) {
      throw MappingError(section + "." + name,
                         "unknown signal; expected one of " + expected + util::did_you_mean(name, signal_names));
    }
  }
}

std::vector<ParameterSetting> check_parameters(const ModelDescription& md, const std::string& fmu,
                                               const FmuMapping& mapping) {
  std::vector<ParameterSetting> out;
  for (const auto& [name, text] : mapping.parameters) {
    const std::string key = "parameters." + name;
    const Variable* v = md.find(name);
    if (!v) throw MappingError(key, fmt::format("{} has no variable '{}'", fmu, name));
    if (v->causality != Causality::kParameter && v->causality != Causality::kInput) {
      throw MappingError(key, fmt::format("{}: variable '{}' has causality {}; only a parameter or an input can be "
                                          "set",
                                          fmu, name, to_string(v->causality)));
    }
    if (v->variability == Variability::kConstant) {
      throw MappingError(key, fmt::format("{}: variable '{}' is a constant", fmu, name));
    }
    ParameterSetting s{v, 0.0};
    switch (v->type) {
      case VariableType::kBoolean:
        if (text == "true" || text == "1") {
          s.number = 1.0;
        } else if (text == "false" || text == "0") {
          s.number = 0.0;
        } else {
          throw MappingError(key, fmt::format("got '{}', expected true or false (a Boolean)", text));
        }
        break;
      case VariableType::kReal:
      case VariableType::kInteger: {
        std::size_t used = 0;
        double d = NAN;
        try {
          d = std::stod(text, &used);
        } catch (const std::exception&) {
          used = 0;
        }
        if (used != text.size() || !std::isfinite(d)) {
          throw MappingError(key, fmt::format("got '{}', expected a finite number", text));
        }
        if (v->type == VariableType::kInteger &&
            (d != std::round(d) || d < static_cast<double>(INT32_MIN) || d > static_cast<double>(INT32_MAX))) {
          throw MappingError(key, fmt::format("got '{}', expected an integer (the variable is Integer)", text));
        }
        if ((v->min && d < *v->min) || (v->max && d > *v->max)) {
          throw MappingError(key, fmt::format("got {}, expected a value in [{}, {}] (the FMU's min and max)", text,
                                              v->min ? fmt::format("{:g}", *v->min) : "-inf",
                                              v->max ? fmt::format("{:g}", *v->max) : "inf"));
        }
        s.number = d;
        break;
      }
      default:
        throw MappingError(key, fmt::format("{}: variable '{}' is {}; a scenario sets Real, Integer and Boolean "
                                            "variables only",
                                            fmu, name, to_string(v->type)));
    }
    out.push_back(s);
  }
  return out;
}

void set_value(Instance& instance, const Variable& v, double number) {
  const ValueReference vr[1] = {v.vr};
  switch (v.type) {
    case VariableType::kReal: {
      const double x[1] = {number};
      instance.set_real(vr, x);
      break;
    }
    case VariableType::kInteger: {
      const std::int32_t x[1] = {static_cast<std::int32_t>(number)};
      instance.set_integer(vr, x);
      break;
    }
    case VariableType::kBoolean: {
      const bool x[1] = {number != 0.0};
      instance.set_boolean(vr, x);
      break;
    }
    default:
      throw FmuError("variable '" + v.name + "' is " + std::string(to_string(v.type)) + ": not set by quadcosim");
  }
}

}  // namespace quadcosim::fmi
