#include "control/controller_config.hpp"

#include <numbers>

namespace quadcosim::control {

namespace {
constexpr double kPi = std::numbers::pi;

using NodeTable = ParameterTable<NodeSettings>;

NodeTable::Entry choice(std::string_view name, std::string_view description, std::vector<std::string_view> choices,
                        bool affects_design, std::function<ParameterValue(const NodeSettings&)> get,
                        std::function<void(NodeSettings&, const ParameterValue&)> set) {
  return NodeTable::Entry{ParameterSpec{name, "choice", description, 0, 0, std::move(choices), affects_design},
                          std::move(get), std::move(set)};
}

NodeTable make_node_table() {
  return NodeTable({
      choice(
          "mode", "attitude: roll/pitch/yaw setpoints + altitude hold; position: x/y/z/yaw (or the trajectory)",
          {"attitude", "position"}, false,
          [](const NodeSettings& c) -> ParameterValue { return to_string(c.setpoint.mode); },
          [](NodeSettings& c, const ParameterValue& v) {
            c.setpoint.mode = std::get<std::string>(v) == "position" ? Mode::kPosition : Mode::kAttitude;
          }),
      NodeTable::number(
          "x_des", "m", -1e5, 1e5, "desired x (east), position mode",
          [](auto& c) -> auto& { return c.setpoint.p_des_W.x(); }, false),
      NodeTable::number(
          "y_des", "m", -1e5, 1e5, "desired y (north), position mode",
          [](auto& c) -> auto& { return c.setpoint.p_des_W.y(); }, false),
      NodeTable::number(
          "z_des", "m", -1e3, 1e5, "desired altitude z (up)", [](auto& c) -> auto& { return c.setpoint.p_des_W.z(); },
          false),
      NodeTable::number(
          "roll_des", "rad", -1.5, 1.5, "desired roll, attitude mode",
          [](auto& c) -> auto& { return c.setpoint.roll_des_rad; }, false),
      NodeTable::number(
          "pitch_des", "rad", -1.5, 1.5, "desired pitch, attitude mode",
          [](auto& c) -> auto& { return c.setpoint.pitch_des_rad; }, false),
      NodeTable::number(
          "yaw_des", "rad", -2 * kPi, 2 * kPi, "desired yaw", [](auto& c) -> auto& { return c.setpoint.yaw_des_rad; },
          false),
      NodeTable::number(
          "stale_limit", "s", 1e-4, 1e4, "sensor data older than this triggers the safety command (Algorithm 1)",
          [](auto& c) -> auto& { return c.stale_limit_s; }, false),
      choice(
          "safety_mode", "safety command: stop (omega_min) or hover (hover speed)", {"stop", "hover"}, false,
          [](const NodeSettings& c) -> ParameterValue { return to_string(c.safety); },
          [](NodeSettings& c, const ParameterValue& v) {
            c.safety = std::get<std::string>(v) == "hover" ? SafetyMode::kHover : SafetyMode::kStop;
          }),
  });
}
}  // namespace

const ParameterTable<NodeSettings>& node_parameters() {
  static const NodeTable table = make_node_table();
  return table;
}

std::vector<const ParameterSpec*> all_parameters(const Controller& controller) {
  std::vector<const ParameterSpec*> out;
  for (const ParameterSpec& s : node_parameters().specs()) out.push_back(&s);
  for (const ParameterSpec& s : controller.parameters()) out.push_back(&s);
  return out;
}

std::optional<ParameterValue> get_parameter(const NodeSettings& node, const Controller& controller,
                                            std::string_view name) {
  if (auto v = node_parameters().get(node, name)) return v;
  return controller.get_parameter(name);
}

std::string set_parameter(NodeSettings& node, Controller& controller, std::string_view name,
                          const ParameterValue& value) {
  if (node_parameters().find(name)) return node_parameters().set(node, name, value);
  const Setting setting{std::string(name), value};
  return controller.set_parameters({&setting, 1});
}

const ParameterSpec* find_parameter(const ControllerConfig& config, std::string_view name) {
  for (const ParameterSpec* s : all_parameters(*config.controller)) {
    if (s->name == name) return s;
  }
  return nullptr;
}

std::vector<const ParameterSpec*> all_parameters(const ControllerConfig& config) {
  return all_parameters(*config.controller);
}

std::optional<ParameterValue> get_parameter(const ControllerConfig& config, std::string_view name) {
  return get_parameter(config.node, *config.controller, name);
}

std::string set_parameter(ControllerConfig& config, std::string_view name, const ParameterValue& value) {
  if (node_parameters().find(name)) return node_parameters().set(config.node, name, value);
  // The configured controller may be shared (swarm vehicles, sweep runs): change a copy.
  std::unique_ptr<Controller> next = config.controller->clone();
  if (std::string err = set_parameter(config.node, *next, name, value); !err.empty()) return err;
  config.controller = std::move(next);
  return {};
}

const char* to_string(SafetyMode mode) { return mode == SafetyMode::kStop ? "stop" : "hover"; }

Reference trajectory_reference(const trajectory::FlatOutput& f, const Eigen::Vector3d& offset_W) {
  Reference r;
  r.mode = Mode::kPosition;
  r.p_W = f.p_W + offset_W;
  r.v_W = f.v_W;
  r.a_W = f.a_W;
  r.j_W = f.j_W;
  r.yaw_rad = f.yaw_rad;
  r.yaw_rate_rad_s = f.yaw_rate_rad_s;
  return r;
}

}  // namespace quadcosim::control
