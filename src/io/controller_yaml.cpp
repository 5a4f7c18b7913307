// io/controller_yaml.hpp: the `controller:` section, FMU specs, and the controller --controller names.
#include "io/controller_yaml.hpp"

#include <fmt/format.h>
#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <string_view>

#include "controllers/registry.hpp"
#include "io/sitl_yaml.hpp"
#include "util/did_you_mean.hpp"

namespace quadcosim::io {

namespace {

control::ParameterValue parameter_value(YamlSection& s, const std::string& key, const control::ParameterSpec& spec,
                                        const YAML::Node& n) {
  if (!n.IsScalar()) s.fail(key, "got " + YamlSection::describe(n) + ", expected a single value");
  if (spec.is_choice()) return n.Scalar();
  s.refuse_quoted_number(key, n);
  try {
    return n.as<double>();
  } catch (const YAML::Exception&) {
    s.fail(key, "got '" + n.Scalar() + "', expected a number");
  }
}

// Reads every leaf of a (possibly nested) mapping as a controller parameter: `altitude: {kp: 4}`
// and `altitude.kp: 4` are the same. The node's parameters are applied as read; the controller's are
// checked against its table as read (so an error names the key) and applied together at the end (one
// design for all of them).
// Parameter names have at most three parts (lqr.roll.q_angle); deeper nesting, as an alias that
// contains itself (`a: &x {b: *x}`) makes, is refused instead of followed.
constexpr int kMaxParameterDepth = 3;

// The keys of a `controller:` section that are not parameters: read by read_controller.
bool controller_section_key(const std::string& key) {
  return key == "type" || key == "fmu" || key == "inputs" || key == "outputs" || key == "parameters" ||
         key == "python" || key == "sitl";
}

// A key of a `controller:` section (or of a schedule's `set:`) named after a registered controller
// type holds that type's gains (`paper: {lqr: ...}`): applied when that type flies, checked against
// its table when another does.
bool type_section_key(const std::string& key) { return controllers::find_controller_type(key) != nullptr; }

// Where a parameter is read from: directly under `controller:` (the node's and the flying
// controller's), or inside a type's gains section (its gains only).
enum class ParameterPlace { kTop, kTypeSection };

void collect_parameters(YamlSection& s, const std::string& prefix, control::ControllerConfig& c,
                        std::vector<control::Setting>& controller_settings,
                        std::vector<std::pair<std::string, control::ParameterValue>>* out, int depth,
                        ParameterPlace place = ParameterPlace::kTop) {
  for (const std::string& key : s.keys()) {
    if (depth == 1 && place == ParameterPlace::kTop && (controller_section_key(key) || type_section_key(key))) {
      continue;  // read by the caller
    }
    if (depth == 1 && place == ParameterPlace::kTop && (key == "in_process" || key == "step_timeout_s") &&
        s.node()["fmu"]) {
      continue;  // an FMU controller's process options: read_fmu_spec's
    }
    const YAML::Node n = s.raw(key);
    const std::string name = prefix.empty() ? key : prefix + "." + key;
    if (n.IsMap()) {
      if (depth >= kMaxParameterDepth) {
        s.fail(key, "unknown controller parameter '" + name + "' (nested too deeply; see `quadcosim params`)");
      }
      YamlSection child(n, s.file(), s.key_path(key));
      collect_parameters(child, name, c, controller_settings, out, depth + 1, place);
      continue;
    }
    const bool node = control::node_parameters().find(name) != nullptr;
    if (node && place == ParameterPlace::kTypeSection) {
      s.fail(key, "'" + name +
                      "' is the node's (what is flown, for every controller type); expected it directly "
                      "under controller:, not in a type's gains section");
    }
    const control::ParameterSpec* spec = control::find_parameter(c, name);
    if (!spec) {
      std::vector<std::string> known;
      for (const control::ParameterSpec* p : control::all_parameters(c)) known.emplace_back(p->name);
      s.fail(key, "unknown parameter '" + name + "' of the node or of controller type '" + std::string(c.type()) +
                      "' (see `quadcosim params --controller " + std::string(c.type()) + "`)" +
                      util::did_you_mean(name, known));
    }
    const control::ParameterValue value = parameter_value(s, key, *spec, n);
    if (node) {
      if (std::string err = control::set_parameter(c, name, value); !err.empty()) s.fail(key, err);
    } else {
      if (std::string err = control::check_value(*spec, value); !err.empty()) s.fail(key, err);
      for (const control::Setting& before : controller_settings) {
        if (before.name == name) {
          s.fail(key, "'" + name + "' is set twice: directly under controller: and in the " + std::string(c.type()) +
                          " gains section; keep one");
        }
      }
      controller_settings.push_back({name, value});
    }
    if (out) out->emplace_back(name, value);
  }
}

// The gains sections of `s` (keys named after registered types): the flying type's into `settings`
// (and `out`), every other checked against its own type's table, as designed for `vehicle`, and left
// unused.
void read_type_sections(YamlSection& s, control::ControllerConfig& c, const model::VehicleParams& vehicle,
                        std::vector<control::Setting>& settings,
                        std::vector<std::pair<std::string, control::ParameterValue>>* out) {
  for (const std::string& key : s.keys()) {
    if (!type_section_key(key)) continue;
    auto section = s.section(key);
    if (!section) continue;  // `paper:` with nothing under it
    if (key == c.type()) {
      collect_parameters(*section, "", c, settings, out, 1, ParameterPlace::kTypeSection);
      continue;
    }
    control::ControllerConfig other;
    try {
      other = controllers::make_config(key, vehicle);
    } catch (const std::exception&) {
      continue;  // not designable for this vehicle; it does not fly here, so its gains are not checked
    }
    std::vector<control::Setting> unused;
    collect_parameters(*section, "", other, unused, nullptr, 1, ParameterPlace::kTypeSection);
    if (unused.empty()) continue;
    std::unique_ptr<control::Controller> probe = other.controller->clone();
    if (std::string err = probe->set_parameters(unused); !err.empty()) section->fail(unused.front().name, err);
  }
}

}  // namespace

void read_parameters(YamlSection& s, control::ControllerConfig& c,
                     std::vector<std::pair<std::string, control::ParameterValue>>* out) {
  std::vector<control::Setting> settings;
  collect_parameters(s, "", c, settings, out, 1);
  read_type_sections(s, c, c.vehicle, settings, out);
  if (settings.empty()) return;
  std::unique_ptr<control::Controller> next = c.controller->clone();
  if (std::string err = next->set_parameters(settings); !err.empty()) s.fail(settings.front().name, err);
  c.controller = std::move(next);
}

namespace {

// A list of FMU variable names under `key` of `s` (one per component of a signal).
std::vector<std::string> variable_names(YamlSection& s, const std::string& key) {
  const YAML::Node n = s.raw(key);
  if (!n.IsSequence()) s.fail(key, "got " + YamlSection::describe(n) + ", expected a list of FMU variable names");
  std::vector<std::string> names;
  for (const YAML::Node& e : n) {
    if (!e.IsScalar() || e.Scalar().empty()) {
      s.fail(key, "got an entry " + YamlSection::describe(e) + ", expected FMU variable names");
    }
    names.push_back(e.Scalar());
  }
  return names;
}

}  // namespace

// The `fmu`, `inputs`, `outputs` and `parameters` keys of a `plant:` or `controller:` section; a
// relative path is taken from `folder` (the scenario file's).
FmuSpec read_fmu_spec(YamlSection& s, const std::filesystem::path& folder) {
  namespace fs = std::filesystem;
  FmuSpec spec;
  const std::string given = s.text("fmu", "");
  if (given.empty()) s.fail("fmu", "missing; expected the path of a co-simulation FMU (.fmu file or unpacked folder)");
  const fs::path full = fs::path(given).is_absolute() ? fs::path(given) : folder / given;
  if (!fs::exists(full)) s.fail("fmu", "got '" + given + "': no such file (" + full.string() + ")");
  spec.path = full.lexically_normal().string();
  // Each FMU instance runs in a child process unless asked otherwise (docs/reliability.md).
  spec.mapping.isolated = !s.boolean("in_process", false);
  // An isolated call that takes longer is given up on (fmi/isolated_instance.hpp); an FMU in
  // quadcosim's own process cannot be stopped inside a call, so a limit there would be a promise not kept.
  if (s.has("step_timeout_s") && !spec.mapping.isolated) {
    s.fail("step_timeout_s",
           "applies to an FMU in its own process; with in_process: true a call cannot be stopped (remove one of "
           "the two keys)");
  }
  spec.mapping.step_timeout_s = s.number("step_timeout_s", spec.mapping.step_timeout_s, 0.0, 1e6);
  for (const char* side : {"inputs", "outputs"}) {
    auto m = s.section(side);
    if (!m) continue;
    auto& target = std::string_view(side) == "inputs" ? spec.mapping.inputs : spec.mapping.outputs;
    for (const std::string& key : m->keys()) target[key] = variable_names(*m, key);
  }
  if (auto p = s.section("parameters")) {
    for (const std::string& key : p->keys()) {
      const YAML::Node n = p->raw(key);
      if (!n.IsScalar()) {
        p->fail(key, "got " + YamlSection::describe(n) +
                         ", expected a single value (an FMU variable's whole name is the key: 'vehicle.mass_kg: 2')");
      }
      spec.mapping.parameters.emplace_back(key, n.Scalar());
    }
  }
  return spec;
}

namespace {

// Runs `make` (which loads and checks an FMU), turning its refusals into ConfigErrors at the key they
// name under `s` (the FMU file itself at `fmu`).
template <class F>
auto checked_fmu(YamlSection& s, F make) -> decltype(make()) {
  try {
    return make();
  } catch (const fmi::MappingError& e) {
    s.fail(e.key(), e.what());
  } catch (const fmi::FmuError& e) {
    s.fail("fmu", e.what());
  }
}

}  // namespace

namespace {

const FmuResolver& fmu_resolver(YamlSection& s, const ScenarioResolvers& resolvers) {
  if (!resolvers.fmu) s.fail("fmu", "this program cannot load FMUs here (it was given no FMU resolver)");
  return *resolvers.fmu;
}

}  // namespace

std::shared_ptr<const sim::ExternalDynamicsFactory> make_plant_fmu(YamlSection& s, const FmuSpec& spec,
                                                                   const ScenarioResolvers& resolvers) {
  const FmuResolver& fmus = fmu_resolver(s, resolvers);
  return checked_fmu(s, [&] { return fmus.plant(spec); });
}

std::shared_ptr<const control::Controller> make_controller_fmu(YamlSection& s, const FmuSpec& spec,
                                                               const model::VehicleParams& vehicle,
                                                               const ScenarioResolvers& resolvers) {
  const FmuResolver& fmus = fmu_resolver(s, resolvers);
  return checked_fmu(s, [&] { return fmus.controller(spec, vehicle); });
}

// Why an FMU controller's inputs of extra sensors (magnetometer.field[1], gnss.fix, ...) do not fit the
// sensors the scenario's vehicle carries, or empty.
std::string controller_sensors_error(const Scenario& sc, const ScenarioResolvers& resolvers) {
  if (!sc.controller.controller || !resolvers.fmu) return {};
  return resolvers.fmu->sensors_error(*sc.controller.controller, sc.simulation.plant.realism.extra_sensors);
}

// A `controller:` section: `type` (default paper) and the parameters, for `vehicle`; or `fmu` (with
// its inputs, outputs and parameters) and the node's and the FMU's parameters; or `python` (type
// python: a class written in Python, resolved by resolvers.python) and the node's
// and the class's declared parameters.
control::ControllerConfig read_controller(YamlSection& s, const model::VehicleParams& vehicle,
                                          const std::filesystem::path& folder, std::optional<FmuSpec>* fmu_spec,
                                          const ScenarioResolvers& resolvers) {
  if (s.has("sitl") || (s.has("type") && s.text("type", "") == "sitl")) {
    if (s.has("type") && s.text("type", "") != "sitl") {
      s.fail("type", "got '" + s.text("type", "") + "' beside sitl; the firmware is the controller (type: sitl)");
    }
    for (const char* key : {"python", "fmu", "inputs", "outputs", "parameters"}) {
      if (s.has(key)) s.fail(key, "beside sitl; a SITL firmware is the controller (docs/sitl.md)");
    }
    control::ControllerConfig c;
    c.vehicle = vehicle;
    c.controller = read_sitl_controller(s, vehicle, folder);
    read_parameters(s, c, nullptr);
    return c;
  }
  if (s.has("python") || (s.has("type") && s.text("type", "") == "python")) {
    if (s.has("type") && s.text("type", "") != "python") {
      s.fail("type",
             "got '" + s.text("type", "") + "' beside python; the Python class is the controller (type: python)");
    }
    if (s.has("fmu")) s.fail("fmu", "beside python; a controller is either an FMU or a Python class");
    for (const char* key : {"inputs", "outputs", "parameters"}) {
      if (s.has(key)) s.fail(key, "belongs to an FMU controller; expected fmu: beside it");
    }
    const std::string target = s.has("python") ? s.text("python", "") : "";
    if (target.empty()) {
      s.fail("python", "missing; expected the controller's class as module:Class (e.g. my_controllers:AltitudePD)");
    }
    const PythonControllerFactory& factory = resolvers.python;
    if (!factory) {
      s.fail("python",
             "this quadcosim was built without Python (or runs without an interpreter), so a controller written in "
             "Python cannot fly here; build with pybind11 and the Python headers (docs/python.md)");
    }
    control::ControllerConfig c;
    c.vehicle = vehicle;
    try {
      c.controller = factory(target, folder, vehicle);
    } catch (const ConfigError&) {
      throw;
    } catch (const std::exception& e) {
      s.fail("python", "got '" + target + "': " + e.what());
    }
    if (!c.controller) s.fail("python", "got '" + target + "': no controller was made");
    read_parameters(s, c, nullptr);
    return c;
  }
  if (s.has("fmu")) {
    if (s.has("type") && s.text("type", "") != "fmu") {
      s.fail("type", "got '" + s.text("type", "") + "' beside fmu; the FMU is the controller (leave type out)");
    }
    const FmuSpec spec = read_fmu_spec(s, folder);
    control::ControllerConfig c;
    c.vehicle = vehicle;
    c.controller = make_controller_fmu(s, spec, vehicle, resolvers);
    read_parameters(s, c, nullptr);
    if (fmu_spec) *fmu_spec = spec;
    return c;
  }
  for (const char* key : {"inputs", "outputs", "parameters"}) {
    if (s.has(key)) s.fail(key, "belongs to an FMU controller; expected fmu: beside it");
  }
  const std::string type =
      s.choice("type", std::string(controllers::kDefaultControllerType), controllers::controller_type_list());
  control::ControllerConfig c;
  try {
    c = controllers::make_config(type, vehicle);
  } catch (const std::exception& e) {
    s.fail("type", "controller '" + type + "' cannot be designed for this vehicle: " + e.what());
  }
  read_parameters(s, c, nullptr);
  return c;
}

namespace {

// `path` from --controller TEXT as an absolute path; std::invalid_argument when there is no such file.
std::string existing_file(const std::string& text, const std::string& path) {
  std::error_code ec;
  if (path.empty() || !std::filesystem::exists(path, ec)) {
    throw std::invalid_argument("got '" + text + "': no such file '" + path + "'");
  }
  return std::filesystem::absolute(path).lexically_normal().string();
}
}  // namespace

ControllerChoice parse_controller_choice(const std::string& text) {
  ControllerChoice c;
  if (text.rfind("python:", 0) == 0) {
    c.kind = ControllerChoice::Kind::kPython;
    c.target = text.substr(7);
    const std::size_t colon = c.target.find(':');
    if (colon == 0 || colon == std::string::npos || colon + 1 == c.target.size()) {
      throw std::invalid_argument("got '" + text +
                                  "', expected python:MODULE:CLASS (e.g. python:my_controllers:LevelPD)");
    }
  } else if (text.rfind("fmu:", 0) == 0) {
    c.kind = ControllerChoice::Kind::kFmu;
    c.target = text.substr(4);
    if (c.target.empty()) throw std::invalid_argument("got '" + text + "', expected fmu:PATH of a co-simulation FMU");
    c.target = existing_file(text, c.target);
  } else if (text == "sitl" || text.rfind("sitl:", 0) == 0) {
    c.kind = ControllerChoice::Kind::kSitl;
    const std::string rest = text.size() > 5 ? text.substr(5) : "ardupilot";
    const std::size_t colon = rest.find(':');
    c.firmware = rest.substr(0, colon);
    if (c.firmware != "ardupilot" && c.firmware != "px4" && c.firmware != "betaflight") {
      throw std::invalid_argument("got '" + text +
                                  "', expected sitl:ardupilot[:BINARY], sitl:px4[:BINARY] or sitl:betaflight[:BINARY] "
                                  "(docs/sitl.md)");
    }
    if (colon != std::string::npos) c.target = existing_file(text, rest.substr(colon + 1));
  } else if (text == "python") {
    c.kind = ControllerChoice::Kind::kPython;  // the class is named by the caller (controller.python)
  } else {
    if (!controllers::find_controller_type(text)) {
      std::vector<std::string> types;
      for (const auto& t : controllers::controller_types()) types.emplace_back(t.name);
      throw std::invalid_argument("got '" + text + "', expected a controller type (" +
                                  controllers::controller_type_names() +
                                  "), python:MODULE:CLASS (a class written in Python), fmu:PATH (an FMU) or "
                                  "sitl:ardupilot|px4|betaflight[:BINARY] "
                                  "(a firmware's SITL build)" +
                                  util::did_you_mean(text, types));
    }
    c.target = text;
  }
  return c;
}

void set_controller_type(YAML::Node root, const std::string& controller) {
  const ControllerChoice choice = parse_controller_choice(controller);
  if (!root["controller"] || !root["controller"].IsMap()) {
    if (root["controller"] && !root["controller"].IsNull()) return;  // load_scenario refuses it, naming the key
    root["controller"] = YAML::Node(YAML::NodeType::Map);
  }
  YAML::Node c = root["controller"];
  // What the file flies: a Python class, an FMU, or a registered type (paper by default).
  const bool was_python = c["python"] || (c["type"] && c["type"].IsScalar() && c["type"].Scalar() == "python");
  const bool was_fmu = static_cast<bool>(c["fmu"]);
  const bool was_sitl = c["sitl"] || (c["type"] && c["type"].IsScalar() && c["type"].Scalar() == "sitl");
  const std::string was_type = was_python                          ? "python"
                               : was_fmu                           ? "fmu"
                               : c["type"] && c["type"].IsScalar() ? c["type"].Scalar()
                                                                   : std::string(controllers::kDefaultControllerType);
  // A SITL firmware flies what the file says of it (its sitl: section: parameters, mission) when it has
  // one for the same firmware.
  const bool same =
      choice.kind == ControllerChoice::Kind::kType ? !was_python && !was_fmu && !was_sitl && was_type == choice.target
      : choice.kind == ControllerChoice::Kind::kSitl
          ? was_sitl && (c["sitl"] && c["sitl"].IsMap() && c["sitl"]["firmware"] && c["sitl"]["firmware"].IsScalar()
                             ? c["sitl"]["firmware"].Scalar()
                             : std::string("ardupilot")) == choice.firmware
      : choice.kind == ControllerChoice::Kind::kPython
          ? was_python && (choice.target.empty() ||
                           (c["python"] && c["python"].IsScalar() && c["python"].Scalar() == choice.target))
          : was_fmu && c["fmu"].IsScalar() && c["fmu"].Scalar() == choice.target;
  if (!same) {
    // The gains written directly under controller: are the file's controller's. A registered type's
    // move into its own section (kept, checked, unused); a Python class's or an FMU's go with it.
    std::vector<std::string> moved;
    for (const auto& kv : c) {
      const std::string key = kv.first.as<std::string>();
      if (controller_section_key(key) || type_section_key(key) || key == "step_timeout_s" || key == "in_process") {
        continue;
      }
      if (control::node_parameters().find(key)) continue;
      moved.push_back(key);
    }
    const bool keep = !was_python && !was_fmu && !was_sitl && controllers::find_controller_type(was_type);
    // A Python class takes the flat gains as its own (its declared parameters, the way a scenario
    // dict passes them with quadcosim.run(..., controller=Class)); they stay where they are.
    if (choice.kind == ControllerChoice::Kind::kPython && keep) moved.clear();
    for (const std::string& key : moved) {
      if (keep) {
        if (!c[was_type] || !c[was_type].IsMap()) c[was_type] = YAML::Node(YAML::NodeType::Map);
        if (!c[was_type][key]) c[was_type][key] = YAML::Clone(c[key]);
      }
      c.remove(key);
    }
    // The other kinds' own keys go; a Python controller's time limit stays for the Python class
    // that replaces it (the scenario's step_timeout_s applies to whichever class flies).
    for (const char* key : {"python", "fmu", "sitl", "inputs", "outputs", "parameters", "in_process"}) c.remove(key);
    if (choice.kind != ControllerChoice::Kind::kPython) c.remove("step_timeout_s");
  }
  switch (choice.kind) {
    case ControllerChoice::Kind::kType: c["type"] = choice.target; break;
    case ControllerChoice::Kind::kPython:
      c["type"] = "python";
      if (!choice.target.empty()) c["python"] = choice.target;
      break;
    case ControllerChoice::Kind::kFmu:
      c.remove("type");
      c["fmu"] = choice.target;
      break;
    case ControllerChoice::Kind::kSitl:
      c["type"] = "sitl";
      if (!c["sitl"] || !c["sitl"].IsMap()) c["sitl"] = YAML::Node(YAML::NodeType::Map);
      c["sitl"]["firmware"] = choice.firmware;
      if (!choice.target.empty()) c["sitl"]["binary"] = choice.target;
      break;
  }
}

}  // namespace quadcosim::io
