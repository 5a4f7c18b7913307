// sweep/key_paths.hpp: the keys a sweep varies, by their YAML path in the scenario.
#include "sweep/key_paths.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <map>
#include <optional>

#include "control/controller_config.hpp"
#include "control/parameters.hpp"
#include "controllers/registry.hpp"
#include "util/did_you_mean.hpp"

namespace quadcosim::sweep {

namespace {

// A vehicle field: a number of the vehicle parameter table (model/vehicle_params.hpp), by its YAML
// path within `vehicle:` ("mass_kg", "motor.tau_up_s", "aero.linear_drag_N_s_m.x").
const model::VehicleParameter* find_field(const std::string& name) {
  const model::VehicleParameter* p = model::find_vehicle_parameter(name);
  return p && p->kind == model::VehicleParameter::Kind::kNumber ? p : nullptr;
}

std::string known_aliases() {
  std::string s;
  for (const auto& [k, _] : vehicle_aliases()) s += (s.empty() ? "" : ", ") + k;
  return s;
}

// "a.b[2].c" -> {"a", "b", "2", "c"}.
std::vector<std::string> split_path(const std::string& path) {
  std::vector<std::string> parts;
  std::string cur;
  for (std::size_t i = 0; i < path.size(); ++i) {
    const char c = path[i];
    if (c == '.' || c == '[' || c == ']') {
      if (!cur.empty()) parts.push_back(cur);
      cur.clear();
    } else {
      cur += c;
    }
  }
  if (!cur.empty()) parts.push_back(cur);
  return parts;
}

// A list index: digits, or x/y/z for the three entries of a vector.
int index_of(const std::string& part) {
  if (part == "x") return 0;
  if (part == "y") return 1;
  if (part == "z") return 2;
  if (part.empty() || part.size() > 6 || !std::all_of(part.begin(), part.end(), ::isdigit)) return -1;
  return std::stoi(part);
}

bool digits(const std::string& part) { return !part.empty() && std::all_of(part.begin(), part.end(), ::isdigit); }

std::string join(const std::vector<std::string>& parts, std::size_t from, std::size_t to) {
  std::string s;
  for (std::size_t i = from; i < to; ++i) s += (i == from ? "" : ".") + parts[i];
  return s;
}

// A vehicle field by its name as the parameter table spells it (entries of a 3-vector as .x/.y/.z:
// "aero.linear_drag_N_s_m[0]" finds "aero.linear_drag_N_s_m.x"); nullptr when it is none.
const model::VehicleParameter* find_vehicle_field(const std::string& name) {
  std::vector<std::string> parts = split_path(name);
  for (std::size_t i = 1; i < parts.size(); ++i) {
    if (parts[i] == "0" || parts[i] == "1" || parts[i] == "2") parts[i] = std::string(1, "xyz"[parts[i][0] - '0']);
  }
  return parts.empty() ? nullptr : find_field(join(parts, 0, parts.size()));
}

void set_at(YAML::Node node, const std::vector<std::string>& parts, std::size_t pos, double value,
            const std::string& path, const std::string& here, const std::map<std::string, std::vector<double>>& lists) {
  const auto at = [&](const std::string& k) { return here.empty() ? k : here + "." + k; };
  if (node.IsSequence()) {
    const int i = index_of(parts[pos]);
    if (i < 0 || i >= static_cast<int>(node.size())) {
      throw PlanError(fmt::format("{}: {} is a list of {}; expected an index 0..{} (or x, y, z), got '{}'", path, here,
                                  node.size(), node.size() - 1, parts[pos]));
    }
    if (pos + 1 == parts.size()) {
      if (node[i].IsMap() || node[i].IsSequence()) throw PlanError(path + ": is a list or mapping, not a number");
      node[i] = value;
      return;
    }
    set_at(node[i], parts, pos + 1, value, path, at(parts[pos]), lists);
    return;
  }
  if (!node.IsMap() && !node.IsNull()) throw PlanError(path + ": " + here + " is a single value, not a mapping");
  if (node.IsMap()) {
    // The longest key present: controller parameters may be written dotted ("altitude.kp: 4").
    const YAML::Node& c = node;
    for (std::size_t j = parts.size(); j > pos; --j) {
      const std::string key = join(parts, pos, j);
      if (!c[key]) continue;
      if (j == parts.size()) {
        if (c[key].IsMap() || c[key].IsSequence()) throw PlanError(path + ": is a list or mapping, not a number");
        node[key] = value;
        return;
      }
      set_at(node[key], parts, j, value, path, at(key), lists);
      return;
    }
  }
  const std::string& key = parts[pos];
  if (pos + 1 == parts.size()) {
    node[key] = value;
    return;
  }
  if (const auto l = lists.find(at(key)); l != lists.end() && index_of(parts[pos + 1]) >= 0) {
    YAML::Node list(YAML::NodeType::Sequence);
    for (double x : l->second) list.push_back(x);
    node[key] = list;
  } else if (digits(parts[pos + 1])) {
    throw PlanError(path + ": " + at(key) +
                    " is not in the scenario file; write the whole list there to vary one entry");
  } else {
    node[key] = YAML::Node(YAML::NodeType::Map);
  }
  set_at(node[key], parts, pos + 1, value, path, at(key), lists);
}

// The number at `parts` in the parsed file, when it is there.
std::optional<double> get_at(const YAML::Node& node, const std::vector<std::string>& parts, std::size_t pos) {
  if (pos == parts.size()) {
    if (!node.IsScalar()) return std::nullopt;
    try {
      return node.as<double>();
    } catch (const YAML::Exception&) {
      return std::nullopt;
    }
  }
  if (node.IsSequence()) {
    const int i = index_of(parts[pos]);
    if (i < 0 || i >= static_cast<int>(node.size())) return std::nullopt;
    return get_at(node[i], parts, pos + 1);
  }
  if (!node.IsMap()) return std::nullopt;
  for (std::size_t j = parts.size(); j > pos; --j) {
    const std::string key = join(parts, pos, j);
    if (node[key]) return get_at(node[key], parts, j);
  }
  return std::nullopt;
}

}  // namespace

// A key path in one spelling, for telling keys apart: list entries as [i] ("initial.position_m.z",
// "initial.position_m[2]" and "initial.position_m.2" are all "initial.position_m[2]"). x, y, z
// after the first part are taken as the indexes 0, 1, 2, as setting the key takes them on a list.
std::string canonical_path(const std::string& path) {
  const std::vector<std::string> parts = split_path(path);
  std::string s;
  for (std::size_t i = 0; i < parts.size(); ++i) {
    const int index = i == 0 ? -1 : index_of(parts[i]);
    s += index >= 0 ? fmt::format("[{}]", index) : fmt::format("{}{}", i == 0 ? "" : ".", parts[i]);
  }
  return s;
}

// Resolves the KEY of a spec into the scenario keys it sets.
std::vector<Key> resolve(const Vary& v, const io::Scenario& nominal, const YAML::Node& root) {
  std::vector<Key> keys;
  const auto vehicle_key = [&](const model::VehicleParameter& f) {
    Key k;
    k.path = "vehicle." + std::string(f.name);
    k.stream = std::string(f.name);
    k.nominal = f.get(nominal.vehicle);
    k.declared = DeclaredRange{f.range.min, f.range.max, "the vehicle parameter table (`quadcosim params --vehicle`)"};
    k.is_vehicle = true;
    return k;
  };
  if (auto a = vehicle_aliases().find(v.name); a != vehicle_aliases().end()) {
    for (const auto& n : a->second) keys.push_back(vehicle_key(*find_field(n)));
    return keys;
  }
  if (const auto* f = find_vehicle_field(v.name)) return {vehicle_key(*f)};
  if (v.name.rfind("vehicle.", 0) == 0) {
    if (const auto* f = find_vehicle_field(v.name.substr(8))) return {vehicle_key(*f)};
  }
  if (v.name.find('.') == std::string::npos) {
    std::vector<std::string> known;
    for (const auto& [alias, fields] : vehicle_aliases()) known.push_back(alias);
    for (const model::VehicleParameter& f : model::vehicle_parameters()) known.emplace_back(f.name);
    throw PlanError("--vary " + v.spec + ": unknown parameter '" + v.name + "' (expected an alias (" + known_aliases() +
                    "), a vehicle field such as mass_kg or motor.tau_up_s, or a scenario key by its YAML path such as "
                    "controller.altitude.kp or initial.position_m[2]; see docs/sweeps.md)" +
                    util::did_you_mean(v.name, known));
  }
  Key k;
  k.path = v.name;
  k.stream = v.name;
  const std::vector<std::string> parts = split_path(v.name);
  k.nominal = get_at(root, parts, 0);
  if (parts[0] == "controller" && parts.size() > 1) {
    // controller.<type>.<gain> names a type's gains section: only the flying type's can be varied.
    const std::string type(nominal.controller.type());
    const bool in_section = parts.size() > 2 && controllers::find_controller_type(parts[1]) != nullptr;
    if (in_section && parts[1] != type) {
      throw PlanError("--vary " + v.spec + ": the scenario flies '" + type + "', not '" + parts[1] +
                      "' (its gains section is not used)");
    }
    const std::string name = join(parts, in_section ? 2 : 1, parts.size());
    const control::ParameterSpec* spec = control::find_parameter(nominal.controller, name);
    if (!spec) {
      std::vector<std::string> known;
      for (const control::ParameterSpec* p : control::all_parameters(nominal.controller)) known.emplace_back(p->name);
      throw PlanError("--vary " + v.spec + ": unknown controller parameter '" + name + "' (see `quadcosim params`)" +
                      util::did_you_mean(name, known));
    }
    if (spec->is_choice()) {
      throw PlanError("--vary " + v.spec + ": controller parameter '" + name + "' is a choice, not a number");
    }
    if (!k.nominal) {
      if (auto value = control::get_parameter(nominal.controller, name)) k.nominal = std::get<double>(*value);
    }
    k.declared = DeclaredRange{spec->min, spec->max, "the controller's parameter table (`quadcosim params`)"};
  } else if (parts[0] == "initial" && parts.size() >= 2 && !k.nominal) {
    if (parts[1] == "yaw_rad" && parts.size() == 2) k.nominal = nominal.initial.yaw_rad;
    if (parts[1] == "position_m" && parts.size() == 3 && index_of(parts[2]) >= 0 && index_of(parts[2]) < 3) {
      k.nominal = nominal.initial.p_W[index_of(parts[2])];
    }
  }
  return {k};
}

const std::map<std::string, std::vector<std::string>>& vehicle_aliases() {
  static const std::map<std::string, std::vector<std::string>> a = {
      {"mass", {"mass_kg"}},
      {"gravity", {"gravity_m_s2"}},
      {"inertia", {"Ixx_kg_m2", "Iyy_kg_m2", "Izz_kg_m2"}},
      {"Ixx", {"Ixx_kg_m2"}},
      {"Iyy", {"Iyy_kg_m2"}},
      {"Izz", {"Izz_kg_m2"}},
      {"arm", {"arm_length_m"}},
      {"kt", {"kt_N_per_rad2_s2"}},
      {"km", {"km_Nm_per_rad2_s2"}},
      {"motor_tau", {"motor.tau_up_s", "motor.tau_down_s"}},
      {"omega_max", {"motor.omega_max_rad_s"}},
      {"linear_drag", {"aero.linear_drag_N_s_m.x", "aero.linear_drag_N_s_m.y", "aero.linear_drag_N_s_m.z"}},
      {"quadratic_drag",
       {"aero.quadratic_drag_N_s2_m2.x", "aero.quadratic_drag_N_s2_m2.y", "aero.quadratic_drag_N_s2_m2.z"}},
      {"rotor_drag", {"aero.rotor_drag_N_s_m_per_rad_s"}},
      {"ground_effect_radius", {"aero.ground_effect_rotor_radius_m"}},
  };
  return a;
}

void set_key(YAML::Node root, const std::string& path, double value,
             const std::map<std::string, std::vector<double>>& lists) {
  std::vector<std::string> parts = split_path(path);
  if (parts.empty()) throw PlanError("empty key");
  // controller.<gain> of a scenario that keeps the flying type's gains in their own section is set
  // there, so the run's file sets it once (the key keeps its name in the sweep's outputs).
  if (parts.size() > 1 && parts[0] == "controller" && !controllers::find_controller_type(parts[1]) &&
      !control::node_parameters().find(join(parts, 1, parts.size()))) {
    const YAML::Node c = static_cast<const YAML::Node&>(root)["controller"];
    const std::string type = c && c.IsMap() && c["type"] && c["type"].IsScalar()
                                 ? c["type"].Scalar()
                                 : std::string(controllers::kDefaultControllerType);
    if (c && c.IsMap() && !c["python"] && !c["fmu"] && c[type] && c[type].IsMap()) {
      parts.insert(parts.begin() + 1, type);
    }
  }
  set_at(root, parts, 0, value, path, "", lists);
}

}  // namespace quadcosim::sweep
