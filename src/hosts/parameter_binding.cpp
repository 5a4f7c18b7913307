#include "hosts/parameter_binding.hpp"

#include "control/parameters.hpp"

namespace quadcosim::hosts {

dds::ParamValue to_ros(const control::ParameterValue& v) {
  if (const auto* s = std::get_if<std::string>(&v)) return dds::ParamValue::of_string(*s);
  return dds::ParamValue::of_double(std::get<double>(v));
}

namespace {

// What set_parameter is given for a ROS value: numbers as doubles, text as text, anything else as
// its type name, so the table refuses it with its usual reason ("z_des must be a number, got 'boolean'").
control::ParameterValue from_ros(const dds::ParamValue& v) {
  switch (v.type) {
    case dds::ParamType::kDouble: return v.double_value;
    case dds::ParamType::kInteger: return static_cast<double>(v.integer_value);
    case dds::ParamType::kString: return v.string_value;
    default: return std::string(dds::type_name(v.type));
  }
}

}  // namespace

dds::ParameterCallbacks controller_parameter_callbacks(sim::ControllerNode& node) {
  dds::ParameterCallbacks cb;
  cb.names = [&node] {
    std::vector<std::string> names;
    for (const auto* p : node.parameters()) names.emplace_back(p->name);
    return names;
  };
  cb.get = [&node](const std::string& name) -> std::optional<dds::ParamValue> {
    const auto v = node.get_parameter(name);
    if (!v) return std::nullopt;
    return to_ros(*v);
  };
  cb.set = [&node](const std::string& name, const dds::ParamValue& value) {
    return node.set_parameter(name, from_ros(value));
  };
  cb.describe = [&node](const std::string& name) -> std::optional<dds::ParamDescriptor> {
    const control::ParameterSpec* spec = nullptr;
    for (const auto* p : node.parameters()) {
      if (p->name == name) spec = p;
    }
    if (!spec) return std::nullopt;
    dds::ParamDescriptor d;
    d.name = std::string(spec->name);
    d.description = std::string(spec->description);
    if (spec->is_choice()) {
      d.type = dds::ParamType::kString;
      d.additional_constraints = "one of:";
      for (auto c : spec->choices) {
        d.additional_constraints += ' ';
        d.additional_constraints.append(c);
      }
    } else {
      d.type = dds::ParamType::kDouble;
      if (!spec->unit.empty()) {
        d.description += " [";
        d.description.append(spec->unit);
        d.description += ']';
      }
      d.floating_point_range = dds::FloatRange{spec->min, spec->max, 0.0};
    }
    if (spec->affects_design) {
      if (!d.additional_constraints.empty()) d.additional_constraints += "; ";
      d.additional_constraints += "changing it re-applies the controller design";
    }
    return d;
  };
  return cb;
}

}  // namespace quadcosim::hosts
