// ROS 2 parameters as rcl_interfaces defines them (ParameterValue, ParameterDescriptor, the six
// parameter services), in plain C++ for the parameter server and client. Nothing here touches DDS.
#pragma once

#include <array>
#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace quadcosim::dds {

/// rcl_interfaces/msg/ParameterType.
enum class ParamType : std::uint8_t {
  kNotSet = 0,
  kBool = 1,
  kInteger = 2,
  kDouble = 3,
  kString = 4,
  kByteArray = 5,
  kBoolArray = 6,
  kIntegerArray = 7,
  kDoubleArray = 8,
  kStringArray = 9,
};

/// "double", "string", "not set", ... as `ros2 param describe` names the types.
std::string_view type_name(ParamType type);

/// rcl_interfaces/msg/ParameterValue: `type` says which field holds the value.
struct ParamValue {
  ParamType type = ParamType::kNotSet;
  bool bool_value = false;
  std::int64_t integer_value = 0;
  double double_value = 0.0;
  std::string string_value;
  std::vector<std::uint8_t> byte_array_value;
  std::vector<bool> bool_array_value;
  std::vector<std::int64_t> integer_array_value;
  std::vector<double> double_array_value;
  std::vector<std::string> string_array_value;

  static ParamValue of_bool(bool v);
  static ParamValue of_integer(std::int64_t v);
  static ParamValue of_double(double v);
  static ParamValue of_string(std::string v);
  bool operator==(const ParamValue&) const = default;
};

/// rcl_interfaces/msg/Parameter.
struct Param {
  std::string name;
  ParamValue value;
  bool operator==(const Param&) const = default;
};

/// rcl_interfaces/msg/SetParametersResult.
struct SetResult {
  bool successful = false;
  std::string reason;  ///< why it was refused ("" on success)
};

/// rcl_interfaces/msg/FloatingPointRange (step 0: any value in the range).
struct FloatRange {
  double from_value = 0.0, to_value = 0.0, step = 0.0;
};
/// rcl_interfaces/msg/IntegerRange.
struct IntRange {
  std::int64_t from_value = 0, to_value = 0;
  std::uint64_t step = 0;
};

/// rcl_interfaces/msg/ParameterDescriptor.
struct ParamDescriptor {
  std::string name;
  ParamType type = ParamType::kNotSet;
  std::string description;
  std::string additional_constraints;
  bool read_only = false;
  bool dynamic_typing = false;
  std::optional<FloatRange> floating_point_range;
  std::optional<IntRange> integer_range;
};

/// rcl_interfaces/msg/ListParametersResult.
struct ListResult {
  std::vector<std::string> names;
  std::vector<std::string> prefixes;
};

/// rcl_interfaces/srv/ListParameters DEPTH_RECURSIVE.
inline constexpr std::uint64_t kDepthRecursive = 0;

/// The six parameter services of a ROS 2 node, named "/<node>/<service>" (rclcpp ParameterService).
enum class ParamService { kGet, kGetTypes, kSet, kSetAtomically, kDescribe, kList };
inline constexpr std::array<ParamService, 6> kParamServices = {ParamService::kGet,      ParamService::kGetTypes,
                                                               ParamService::kSet,      ParamService::kSetAtomically,
                                                               ParamService::kDescribe, ParamService::kList};
/// Position of `service` in kParamServices (and in per-service tables).
inline constexpr std::size_t index(ParamService service) { return static_cast<std::size_t>(service); }
/// "get_parameters", "get_parameter_types", "set_parameters", "set_parameters_atomically",
/// "describe_parameters", "list_parameters".
std::string_view service_suffix(ParamService service);

/// A node's namespace and name, e.g. {"/", "attitude_controller"} or {"/uav1", "attitude_controller"}.
struct NodeName {
  std::string ns = "/";
  std::string name;
  /// "/attitude_controller", "/uav1/attitude_controller".
  std::string fully_qualified() const;
};

/// Parses "attitude_controller", "/attitude_controller" or "/uav1/attitude_controller" (namespace "/"
/// unless given). Throws std::invalid_argument naming the text unless every token is a valid ROS
/// name token ([A-Za-z_][A-Za-z0-9_]*).
NodeName parse_node_name(std::string_view text);

/// DDS topics of a node's service, as rmw_cyclonedds names them:
/// "rq/attitude_controller/set_parametersRequest" and "rr/attitude_controller/set_parametersReply".
std::string request_topic(const NodeName& node, ParamService service);
std::string reply_topic(const NodeName& node, ParamService service);

/// rclcpp's ListParameters rule: with no prefixes and depth 0 every name; otherwise a name is listed
/// when it has fewer than `depth` '.' separators (no prefixes), or equals a prefix, or continues a
/// prefix after a '.' with fewer than `depth` further separators (any number when depth is 0).
/// `prefixes` of the result: the distinct parts before the last '.' of the listed names.
ListResult list_parameters(const std::vector<std::string>& declared, const std::vector<std::string>& prefixes,
                           std::uint64_t depth);

/// A double as Python's repr prints it, hence as `ros2 param get` shows it: "10.0", "0.1", "1e-05",
/// "1e+16", "nan", "inf", "-0.0".
std::string python_float(double v);

/// The line `ros2 param get` prints for a value: "Double value is: 10.0", "String value is:
/// attitude", "Integer value is: 3", "Boolean value is: True", "Double values are: [1.0, 2.5]",
/// "Parameter not set.".
std::string ros2_get_line(const ParamValue& v);

/// A value typed on a command line, as `ros2 param set` reads it (a YAML scalar): true/false (and
/// YAML 1.1's yes/no/on/off, in lower, Title or UPPER case) -> BOOL; a whole decimal number -> INTEGER;
/// another number ("10.0", "-.5", ".inf") -> DOUBLE; anything else -> STRING. Unlike PyYAML, "1e3"
/// (no '.' or exponent sign) is read as the DOUBLE 1000, not as a string.
ParamValue parse_param_value(std::string_view text);

}  // namespace quadcosim::dds
