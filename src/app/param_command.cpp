// `quadcosim param get|set|list|describe NODE ...`: a ROS 2 node's parameters over DDS, through its
// parameter services (ours or an rmw_cyclonedds_cpp node's), printed as `ros2 param` prints them.
#include <CLI/CLI.hpp>

#include <algorithm>
#include <iostream>

#include "app/commands.hpp"
#include "app/exit_codes.hpp"
#include "dds/parameter_client.hpp"

namespace quadcosim::app {

std::string check_node_name(const std::string& text) {
  try {
    dds::parse_node_name(text);
    return {};
  } catch (const std::invalid_argument& e) {
    return e.what();
  }
}

CLI::App* add_param_subcommand(CLI::App& app, ParamOptions& o) {
  auto* param = app.add_subcommand("param", "get, set and list a ROS 2 node's parameters (no ROS 2 needed)");
  param->require_subcommand(1);
  auto node_arg = [&o](CLI::App* verb) {
    verb->add_option("node", o.node, "ROS node name, e.g. /attitude_controller")
        ->required()
        ->check(CLI::Validator(check_node_name, "NODE"));
    verb->add_option("--timeout", o.timeout_s, "how long to look for the node and wait for its answer [s]")
        ->check(CLI::Range(0.01, 3600.0));
    add_enclave_option(verb, o.enclave);
  };

  auto* get = param->add_subcommand("get", "print a parameter's value, as `ros2 param get`");
  node_arg(get);
  get->add_option("name", o.name, "parameter name, e.g. z_des")->required();
  get->callback([&o] { o.verb = "get"; });

  auto* set = param->add_subcommand("set", "set a parameter, as `ros2 param set`");
  node_arg(set);
  set->add_option("name", o.name, "parameter name, e.g. z_des")->required();
  set->add_option("value", o.value, "new value: 10 (integer), 10.0 (double), true (boolean), other text (string)")
      ->required();
  set->callback([&o] { o.verb = "set"; });

  auto* list = param->add_subcommand("list", "list a node's parameter names, as `ros2 param list NODE`");
  node_arg(list);
  list->add_option("--param-prefixes", o.prefixes, "only names with these prefixes");
  list->callback([&o] { o.verb = "list"; });

  auto* describe = param->add_subcommand("describe", "a parameter's type, meaning and range, as `ros2 param describe`");
  node_arg(describe);
  describe->add_option("name", o.name, "parameter name, e.g. z_des")->required();
  describe->callback([&o] { o.verb = "describe"; });
  return param;
}

namespace {

int not_set(const dds::NodeName& node, const std::string& name) {
  std::cerr << "Parameter not set: node " << node.fully_qualified() << " has no parameter '" << name << "'\n";
  return exit_code::kFailed;
}

void print_descriptor(const dds::ParamDescriptor& d) {
  std::cout << "Parameter name: " << d.name << '\n';
  std::cout << "  Type: " << dds::type_name(d.type) << '\n';
  if (!d.description.empty()) std::cout << "  Description: " << d.description << '\n';
  std::cout << "  Constraints:\n";
  if (d.read_only) std::cout << "    Read only: true\n";
  if (d.floating_point_range) {
    std::cout << "    Min value: " << dds::python_float(d.floating_point_range->from_value) << '\n';
    std::cout << "    Max value: " << dds::python_float(d.floating_point_range->to_value) << '\n';
    if (d.floating_point_range->step != 0.0) {
      std::cout << "    Step: " << dds::python_float(d.floating_point_range->step) << '\n';
    }
  } else if (d.integer_range) {
    std::cout << "    Min value: " << d.integer_range->from_value << '\n';
    std::cout << "    Max value: " << d.integer_range->to_value << '\n';
    if (d.integer_range->step != 0) std::cout << "    Step: " << d.integer_range->step << '\n';
  }
  if (!d.additional_constraints.empty()) {
    std::cout << "    Additional constraints: " << d.additional_constraints << '\n';
  }
}

}  // namespace

int param_command(const ParamOptions& o) {
  const dds::NodeName node = dds::parse_node_name(o.node);
  const auto timeout_ns = static_cast<std::int64_t>(o.timeout_s * 1e9);
  dds::ParameterClient client(dds::read_ros_environment(o.enclave), node);
  if (o.verb == "get") {
    const auto values = client.get({o.name}, timeout_ns);
    if (values.empty()) return not_set(node, o.name);
    std::cout << dds::ros2_get_line(values.front()) << '\n';
    return exit_code::kOk;
  }
  if (o.verb == "set") {
    const auto results = client.set({{o.name, dds::parse_param_value(o.value)}}, timeout_ns);
    if (results.size() != 1) {
      std::cerr << "error: node " << node.fully_qualified() << " answered set_parameters with " << results.size()
                << " results for 1 parameter\n";
      return exit_code::kOutput;
    }
    if (!results.front().successful) {
      std::cerr << "Setting parameter failed" << (results.front().reason.empty() ? "" : ": ") << results.front().reason
                << '\n';
      return exit_code::kFailed;
    }
    std::cout << "Set parameter successful" << (results.front().reason.empty() ? "" : ": ") << results.front().reason
              << '\n';
    return exit_code::kOk;
  }
  if (o.verb == "list") {
    auto names = client.list(o.prefixes, dds::kDepthRecursive, timeout_ns).names;
    std::sort(names.begin(), names.end());
    for (const auto& n : names) std::cout << "  " << n << '\n';
    return exit_code::kOk;
  }
  if (o.verb == "describe") {
    const auto descriptors = client.describe({o.name}, timeout_ns);
    if (descriptors.empty()) return not_set(node, o.name);
    print_descriptor(descriptors.front());
    return exit_code::kOk;
  }
  std::cerr << "error: param: unknown verb '" << o.verb << "'\n";
  return exit_code::kBadInput;
}

}  // namespace quadcosim::app
