// Runtime parameters, declared once: name, unit, range, meaning, and where the value lives. Scenario
// files, `quadcosim param`, sweeps and (over DDS) the ROS 2 parameter services all go through these
// declarations, so a parameter is spelt and checked the same everywhere. A controller declares its
// table with ParameterTable<Params> over its own parameter struct; the controller node declares the
// setpoints and the stale-data safety the same way (control/controller_config.hpp).
#pragma once

#include <functional>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <utility>
#include <variant>
#include <vector>

namespace quadcosim::control {

using ParameterValue = std::variant<double, std::string>;

/// The declaration of one parameter.
struct ParameterSpec {
  std::string_view name;
  std::string_view unit;  ///< SI unit, "" when dimensionless, "choice" for string parameters
  std::string_view description;
  double min = 0.0, max = 0.0;            ///< inclusive range of a numeric parameter
  std::vector<std::string_view> choices;  ///< allowed values of a string parameter
  /// True when changing it re-applies the controller's design (gains, LQR), not just a setpoint.
  bool affects_design = false;

  bool is_choice() const { return !choices.empty(); }
};

/// "" when `value` fits `spec` (a number in range, or one of the choices), else why not
/// ("z_des must be in [-1000, 100000] m, got nan").
std::string check_value(const ParameterSpec& spec, const ParameterValue& value);

/// "10" / "attitude": a value as text for tables and logs (numbers in shortest round-trip form).
std::string to_string(const ParameterValue& value);

/// "unknown parameter 'z_dse'".
std::string unknown_parameter(std::string_view name);
/// "unknown parameter 'z_dse'; did you mean 'z_des'?" when one of `known` is close.
std::string unknown_parameter(std::string_view name, std::span<const ParameterSpec> known);

/// A parameter table over a parameter struct P: each declaration with how to read and write its value.
template <class P>
class ParameterTable {
 public:
  struct Entry {
    ParameterSpec spec;
    std::function<ParameterValue(const P&)> get;
    std::function<void(P&, const ParameterValue&)> set;
  };

  /// A numeric parameter stored in the double `field(p)` returns; `field` is generic over const
  /// ([](auto& p) -> auto& { return p.altitude.kp; }).
  template <class Field>
  static Entry number(std::string_view name, std::string_view unit, double min, double max,
                      std::string_view description, Field field, bool affects_design = true) {
    return Entry{ParameterSpec{name, unit, description, min, max, {}, affects_design},
                 [field](const P& p) -> ParameterValue { return double{field(p)}; },
                 [field](P& p, const ParameterValue& v) { field(p) = std::get<double>(v); }};
  }

  explicit ParameterTable(std::vector<Entry> entries) : entries_(std::move(entries)) {
    for (const auto& e : entries_) specs_.push_back(e.spec);
  }

  std::span<const ParameterSpec> specs() const { return specs_; }

  const Entry* find(std::string_view name) const {
    for (const auto& e : entries_) {
      if (e.spec.name == name) return &e;
    }
    return nullptr;
  }

  std::optional<ParameterValue> get(const P& p, std::string_view name) const {
    const Entry* e = find(name);
    if (!e) return std::nullopt;
    return e->get(p);
  }

  /// Checks and applies one value; "" on success, else why it was refused (then `p` is unchanged).
  std::string set(P& p, std::string_view name, const ParameterValue& value) const {
    const Entry* e = find(name);
    if (!e) return unknown_parameter(name, specs_);
    if (std::string err = check_value(e->spec, value); !err.empty()) return err;
    e->set(p, value);
    return {};
  }

 private:
  std::vector<Entry> entries_;
  std::vector<ParameterSpec> specs_;
};

}  // namespace quadcosim::control
