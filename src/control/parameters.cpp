#include "control/parameters.hpp"

#include <charconv>
#include <cmath>
#include <sstream>

#include "util/did_you_mean.hpp"

namespace quadcosim::control {

std::string to_string(const ParameterValue& value) {
  if (const auto* s = std::get_if<std::string>(&value)) return *s;
  char buf[32];
  const auto r = std::to_chars(buf, buf + sizeof buf, std::get<double>(value));  // shortest round trip
  return std::string(buf, r.ptr);
}

std::string unknown_parameter(std::string_view name) { return "unknown parameter '" + std::string(name) + "'"; }

std::string unknown_parameter(std::string_view name, std::span<const ParameterSpec> known) {
  std::vector<std::string> names;
  for (const ParameterSpec& s : known) names.emplace_back(s.name);
  return unknown_parameter(name) + util::did_you_mean(name, names);
}

std::string check_value(const ParameterSpec& spec, const ParameterValue& value) {
  std::ostringstream err;
  if (spec.is_choice()) {
    const auto* s = std::get_if<std::string>(&value);
    bool ok = false;
    if (s) {
      for (auto c : spec.choices) ok = ok || c == *s;
    }
    if (ok) return {};
    err << spec.name << " must be one of";
    for (auto c : spec.choices) err << " '" << c << "'";
    err << ", got '" << to_string(value) << "'";
    return err.str();
  }
  const auto* d = std::get_if<double>(&value);
  if (!d) return std::string(spec.name) + " must be a number, got '" + to_string(value) + "'";
  if (std::isfinite(*d) && *d >= spec.min && *d <= spec.max) return {};
  err << spec.name << " must be in [" << spec.min << ", " << spec.max << "]";
  if (!spec.unit.empty()) err << " " << spec.unit;
  err << ", got " << to_string(value);
  return err.str();
}

}  // namespace quadcosim::control
