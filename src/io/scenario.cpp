#include "io/scenario.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <map>
#include <mutex>
#include <string_view>

#include "analysis/step_metrics.hpp"
#include "analysis/tracking.hpp"
#include "controllers/registry.hpp"
#include "fmi/fmu_controller.hpp"
#include "fmi/fmu_plant.hpp"
#include "io/criteria_yaml.hpp"
#include "io/realism_yaml.hpp"
#include "io/scenario_limits.hpp"
#include "io/sitl_yaml.hpp"
#include "io/trajectory_yaml.hpp"
#include "io/yaml_reader.hpp"
#include "sim/topics.hpp"
#include "util/did_you_mean.hpp"

namespace quadcosim::io {

namespace {

constexpr double kHuge = 1e12;

// Reads every entry of the vehicle parameter table from its place in `root` (top level, or the
// `motor:` / `aero:` sections; a 3-vector's .x/.y/.z entries are one list of three), each checked
// against its declared range, then the rules between fields (model::validate).
void read_vehicle(YamlSection& root, model::VehicleParams& v) {
  std::map<std::string, std::optional<YamlSection>, std::less<>> sections;
  auto section = [&](std::string_view name) -> YamlSection* {
    if (name.empty()) return &root;
    auto it = sections.find(name);
    if (it == sections.end()) it = sections.emplace(std::string(name), root.section(std::string(name))).first;
    return it->second ? &*it->second : nullptr;
  };
  const auto& table = model::vehicle_parameters();
  for (std::size_t i = 0; i < table.size(); ++i) {
    const model::VehicleParameter& p = table[i];
    YamlSection* s = section(p.section());
    if (!s) continue;
    const std::string key(p.key());
    switch (p.kind) {
      case model::VehicleParameter::Kind::kNumber:
        if (p.component() < 0) {
          p.ref(v) = s->number(key, p.get(v), p.range);
        } else if (p.component() == 0) {
          // Entries i, i+1, i+2 are the vector's x, y, z.
          const auto got = s->numbers(key, {p.get(v), table[i + 1].get(v), table[i + 2].get(v)}, 3);
          for (int c = 0; c < 3; ++c) {
            const model::VehicleParameter& e = table[i + static_cast<std::size_t>(c)];
            if (!e.range.contains(got[static_cast<std::size_t>(c)])) {
              s->fail(key, fmt::format("got an entry {:g}, expected numbers in {}", got[static_cast<std::size_t>(c)],
                                       e.range.text()));
            }
            e.ref(v) = got[static_cast<std::size_t>(c)];
          }
        }
        break;
      case model::VehicleParameter::Kind::kChoice: {
        const std::vector<std::string> choices(p.choices.begin(), p.choices.end());
        p.set_choice(v, s->choice(key, std::string(p.choice_of(v)), choices));
        break;
      }
      case model::VehicleParameter::Kind::kSigns:
        if (s->has(key)) {
          const auto got = s->numbers(key, {}, 4);
          for (int r = 0; r < 4; ++r) {
            const double g = got[static_cast<std::size_t>(r)];
            if (g != 1.0 && g != -1.0) {
              s->fail(key, fmt::format("got [{:g}, {:g}, {:g}, {:g}], expected four entries, each 1 or -1", got[0],
                                       got[1], got[2], got[3]));
            }
            p.signs(v)[static_cast<std::size_t>(r)] = static_cast<int>(g);
          }
        }
        break;
    }
  }
  for (auto& [name, s] : sections) {
    if (s) s->reject_unknown_keys();
  }
  root.reject_unknown_keys();
  if (std::string err = model::validate(v); !err.empty()) {
    // validate() names the field first ("spin must ..."): report it at that key.
    const std::string field = err.substr(0, err.find(' '));
    if (model::find_vehicle_parameter(field) && field.size() < err.size()) {
      root.fail(field, err.substr(field.size() + 1));
    }
    root.fail("", err);
  }
}

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

// One FMU's loaded description and binary per file, shared by every scenario that names it while any
// of them lives (a sweep loads its scenario once per run).
std::shared_ptr<fmi::Fmu> load_fmu(const std::string& path) {
  static std::mutex mutex;
  static std::map<std::string, std::pair<std::filesystem::file_time_type, std::weak_ptr<fmi::Fmu>>> cache;
  std::error_code ec;
  const auto mtime = std::filesystem::last_write_time(path, ec);
  const std::lock_guard lock(mutex);
  auto& entry = cache[path];
  if (auto fmu = entry.second.lock(); fmu && !ec && entry.first == mtime) return fmu;
  std::shared_ptr<fmi::Fmu> fmu = fmi::Fmu::load(path);
  entry = {mtime, fmu};
  return fmu;
}

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

std::shared_ptr<const sim::ExternalDynamicsFactory> make_plant_fmu(YamlSection& s, const FmuSpec& spec) {
  return checked_fmu(s, [&] { return std::make_shared<const fmi::FmuPlant>(load_fmu(spec.path), spec.mapping); });
}

std::shared_ptr<const control::Controller> make_controller_fmu(YamlSection& s, const FmuSpec& spec,
                                                               const model::VehicleParams& vehicle) {
  return checked_fmu(s, [&]() -> std::shared_ptr<const control::Controller> {
    return std::make_shared<fmi::FmuController>(load_fmu(spec.path), spec.mapping, vehicle);
  });
}

// Why an FMU controller's inputs of extra sensors (magnetometer.field[1], gnss.fix, ...) do not fit the
// sensors the scenario's vehicle carries, or empty.
std::string controller_sensors_error(const Scenario& sc) {
  if (!sc.controller.controller) return {};
  const fmi::FmuController* fmu = fmi::fmu_controller(*sc.controller.controller);
  return fmu ? fmu->check_sensors(sc.simulation.plant.realism.extra_sensors) : std::string();
}

std::mutex python_factory_mutex;
PythonControllerFactory python_factory;

PythonControllerFactory python_controller_factory() {
  const std::lock_guard lock(python_factory_mutex);
  return python_factory;
}

// A `controller:` section: `type` (default paper) and the parameters, for `vehicle`; or `fmu` (with
// its inputs, outputs and parameters) and the node's and the FMU's parameters; or `python` (type
// python: a class written in Python, resolved by the installed PythonControllerFactory) and the node's
// and the class's declared parameters.
control::ControllerConfig read_controller(YamlSection& s, const model::VehicleParams& vehicle,
                                          const std::filesystem::path& folder, std::optional<FmuSpec>* fmu_spec) {
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
    const PythonControllerFactory factory = python_controller_factory();
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
    c.controller = make_controller_fmu(s, spec, vehicle);
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

// A time in seconds that must fall on a whole plant tick.
sim::Tick tick_at(YamlSection& s, const std::string& key, double seconds, std::int64_t period_ns) {
  const double ticks = seconds * 1e9 / static_cast<double>(period_ns);
  const double whole = std::round(ticks);
  if (std::abs(ticks - whole) > 1e-6) {
    s.fail(key, "got " + fmt::format("{:g}", seconds) + " s, expected a whole number of plant periods (" +
                    fmt::format("{:g}", static_cast<double>(period_ns) / 1e9) + " s)");
  }
  return static_cast<sim::Tick>(whole);
}

void read_simulation(YamlSection& s, sim::SimulationConfig& cfg, double& duration_s) {
  const double plant_hz = s.number("plant_rate_hz", 100.0, 1e-3, 1e6);
  if (const Limits& l = limits(); l.enabled && plant_hz > l.plant_rate_hz) {
    s.fail("plant_rate_hz", fmt::format("got {:g} Hz, more than the limit of {:g} Hz ({})", plant_hz, l.plant_rate_hz,
                                        limit_hint("plant_rate_hz")));
  }
  const double period_ns = 1e9 / plant_hz;
  if (std::abs(period_ns - std::round(period_ns)) > 1e-6) {
    s.fail("plant_rate_hz",
           "got " + fmt::format("{:g}", plant_hz) + ", expected a rate whose period is a whole number of nanoseconds");
  }
  cfg.plant.clock.period_ns = static_cast<std::int64_t>(std::round(period_ns));
  const double controller_hz = s.number("controller_rate_hz", 50.0, 1e-3, plant_hz);
  const double divider = plant_hz / controller_hz;
  if (std::abs(divider - std::round(divider)) > 1e-9) {
    s.fail("controller_rate_hz", "got " + fmt::format("{:g}", controller_hz) +
                                     ", expected a whole divisor of plant_rate_hz (" + fmt::format("{:g}", plant_hz) +
                                     ")");
  }
  cfg.controller_divider = static_cast<int>(std::round(divider));
  cfg.plant.substeps = static_cast<int>(s.integer("substeps", 1, 1, 10000));
  cfg.plant.command_delay_ticks = static_cast<int>(s.integer("command_delay_ticks", 0, 0, 100000));
  duration_s = s.number("duration_s", 15.0, 0.0, 1e7);
  cfg.duration_ticks = tick_at(s, "duration_s", duration_s, cfg.plant.clock.period_ns);
  cfg.ns = s.text("namespace", cfg.ns);
  if (std::string err = sim::validate_namespace(cfg.ns); !err.empty()) s.fail("namespace", err);
  // The vehicle for 3D views: /tf, /tf_static, robot_description and the recorded scene.
  cfg.plant.publish_tf = s.boolean("tf", true);
  const double watchdog_s = s.number("watchdog_s", 0.5, 0.0, 1e6);
  cfg.plant.watchdog_ticks = tick_at(s, "watchdog_s", watchdog_s, cfg.plant.clock.period_ns);
  cfg.plant.watchdog_policy = s.choice("watchdog_policy", "stop", {"hold", "stop"}) == "hold"
                                  ? sim::WatchdogPolicy::kHold
                                  : sim::WatchdogPolicy::kStop;
  s.reject_unknown_keys();
}

// `message_faults:` message loss and delay injected by the in-process transport. Defaults apply to the
// four topics between plant and controller (Pose, Velocity, Imu, motor_commands); `topics:` sets
// any of the vehicle's topics by its name within the namespace.
void read_faults(YamlSection& f, const sim::SimulationConfig& cfg, sim::FaultConfig& out) {
  out.seed = static_cast<std::uint64_t>(f.integer("seed", 1, 0, 9007199254740991LL));
  sim::TopicFaults all;
  all.drop_probability = f.number("drop_probability", 0.0, 0.0, 1.0);
  all.delay_ticks = f.integer("delay_ticks", 0, 0, 100000);
  const sim::Topics t = sim::Topics::for_namespace(cfg.ns);
  const std::map<std::string, std::string> by_name = {{"motor_commands", t.motor_commands},
                                                      {"Pose", t.pose},
                                                      {"Velocity", t.velocity},
                                                      {"Imu", t.imu},
                                                      {"clock", t.clock},
                                                      {"controller_status", t.controller_status}};
  for (const std::string* name : {&t.pose, &t.velocity, &t.imu, &t.motor_commands}) out.topics[*name] = all;
  if (auto per = f.section("topics")) {
    for (const std::string& key : per->keys()) {
      const auto it = by_name.find(key);
      if (it == by_name.end()) {
        std::vector<std::string> known;
        for (const auto& [name, topic] : by_name) known.push_back(name);
        per->fail(key, "unknown topic; expected motor_commands, Pose, Velocity, Imu, clock or controller_status" +
                           util::did_you_mean(key, known));
      }
      auto one = per->section(key);
      if (!one) per->fail(key, "expected a mapping with drop_probability and/or delay_ticks");
      sim::TopicFaults tf = out.topics.count(it->second) ? out.topics[it->second] : sim::TopicFaults{};
      tf.drop_probability = one->number("drop_probability", tf.drop_probability, 0.0, 1.0);
      tf.delay_ticks = one->integer("delay_ticks", tf.delay_ticks, 0, 100000);
      one->reject_unknown_keys();
      out.topics[it->second] = tf;
    }
  }
  f.reject_unknown_keys();
}

// analysis.limits: each key an upper bound >= 0 on a saturation or control-effort figure, at the top
// of the section (a specification, as the keys were read before the two sets existed) or under its
// `spec:` and `paper:`.
LimitsSpec read_limits(YamlSection& limits, double duration_s) {
  LimitsSpec spec;
  const auto read_set = [&](YamlSection& l, CriteriaSet set) {
    auto bound = [&](const std::string& key, double hi, const std::vector<std::string>& figures) {
      if (!l.has(key)) return;
      const double v = l.number(key, 0.0, 0.0, hi);
      for (const auto& f : figures) spec.criteria.push_back(Criterion{f, std::nullopt, v, set});
    };
    bound("max_saturated_s", duration_s, {"saturated_s"});
    bound("max_rotor_saturated_s", duration_s,
          {"rotor1_saturated_s", "rotor2_saturated_s", "rotor3_saturated_s", "rotor4_saturated_s"});
    bound("max_tilt_saturated_s", duration_s, {"tilt_saturated_s"});
    bound("max_rms_u1_deviation_n", kHuge, {"rms_u1_deviation_n"});
  };
  const bool sets = limits.has("spec") || limits.has("paper");
  if (sets) {
    for (const auto& key : limits.node()) {
      const std::string name = key.first.as<std::string>("");
      if (name != "spec" && name != "paper") {
        limits.fail(name, "beside spec/paper; with spec: or paper: every bound goes under one of them");
      }
    }
    if (auto s = limits.section("spec")) {
      read_set(*s, CriteriaSet::kSpec);
      s->reject_unknown_keys();
    }
    if (auto p = limits.section("paper")) {
      read_set(*p, CriteriaSet::kPaper);
      p->reject_unknown_keys();
    }
  } else {
    read_set(limits, CriteriaSet::kSpec);
  }
  limits.reject_unknown_keys();
  return spec;
}

// analysis.tracking: after_s and the bands on the tracking figures, as a step's.
TrackingSpec read_tracking(YamlSection& s, double duration_s) {
  TrackingSpec spec;
  spec.after_s = s.number("after_s", 0.0, 0.0, duration_s);
  auto criteria = read_criteria_sets(s, analysis::tracking_figure_names(), "tracking figure");
  if (!criteria) s.fail("spec", "missing; expected e.g. spec: {position_rmse_m: [null, 0.05]}");
  spec.criteria = std::move(*criteria);
  if (spec.criteria.empty()) s.fail("spec", "expected at least one figure");
  s.reject_unknown_keys();
  return spec;
}

void read_steps(YamlSection& analysis, Scenario& sc, double duration_s) {
  std::vector<StepSpec>& steps = sc.steps;
  if (auto h = analysis.section("hold")) sc.hold = read_hold(*h, duration_s);
  if (auto l = analysis.section("limits")) sc.limits = read_limits(*l, duration_s);
  if (auto t = analysis.section("tracking")) sc.tracking = read_tracking(*t, duration_s);
  const std::vector<std::string> channels = {"x", "y", "z", "roll", "pitch", "yaw"};
  int index = 0;
  for (const YAML::Node& n : analysis.sequence("steps")) {
    const std::string where = "steps[" + std::to_string(index++) + "]";
    if (!n.IsMap()) analysis.fail(where, "expected a mapping with channel, at_s, spec and/or paper");
    YamlSection s(n, analysis.file(), analysis.key_path(where));
    StepSpec step;
    step.channel = s.choice("channel", "", channels);
    if (step.channel.empty()) s.fail("channel", "missing; expected one of x y z roll pitch yaw");
    step.t_step_s = s.number("at_s", 0.0, 0.0, duration_s);
    step.settling_band = s.number("settling_band_pct", 2.0, 0.01, 50.0) / 100.0;
    if (auto criteria = read_criteria_sets(s, analysis::figure_names(), "step figure")) {
      step.criteria = std::move(*criteria);
    }
    if (auto r = s.section("reference")) {
      for (const std::string& key : r->keys()) {
        if (key == "source") {
          step.reference_source = r->text("source", "");
          continue;
        }
        step.reference[key] = r->number(key, 0.0, -kHuge, kHuge);
      }
    }
    s.reject_unknown_keys();
    steps.push_back(step);
  }
  analysis.reject_unknown_keys();
}

void read_schedule(YamlSection& root, Scenario& sc, double duration_s) {
  int index = 0;
  const std::vector<YAML::Node> entries = root.sequence("schedule");
  if (const Limits& l = limits(); l.enabled && entries.size() > l.schedule_entries) {
    root.fail("schedule", fmt::format("{} entries, more than the limit of {} ({})", entries.size(), l.schedule_entries,
                                      limit_hint("schedule_entries")));
  }
  for (const YAML::Node& n : entries) {
    const std::string where = "schedule[" + std::to_string(index++) + "]";
    if (!n.IsMap()) root.fail(where, "expected a mapping with at_s and set");
    YamlSection s(n, root.file(), root.key_path(where));
    const double at = s.number("at_s", 0.0, 0.0, duration_s);
    const sim::Tick tick = tick_at(s, "at_s", at, sc.simulation.plant.clock.period_ns);
    auto set = s.section("set");
    if (!set) s.fail("set", "missing; expected a mapping of parameter: value");
    // Validate against a scratch config, so errors name this entry.
    control::ControllerConfig scratch = sc.controller;
    std::vector<std::pair<std::string, control::ParameterValue>> values;
    if (set->has("type")) set->fail("type", "the controller's type cannot change during a run");
    for (const char* key : {"python", "fmu", "inputs", "outputs", "parameters"}) {
      if (set->has(key)) set->fail(key, "the controller cannot change during a run (only its parameters)");
    }
    read_parameters(*set, scratch, &values);
    for (auto& [name, value] : values) sc.schedule.push_back({tick, name, value});
    if (const Limits& l = limits(); l.enabled && sc.schedule.size() > l.schedule_entries) {
      root.fail(where, fmt::format("the schedule sets more than {} parameter values ({})", l.schedule_entries,
                                   limit_hint("schedule_entries")));
    }
    s.reject_unknown_keys();
  }
}

void read_swarm(YamlSection& s, SwarmSpec& spec) {
  auto& l = spec.layout;
  l.vehicles = static_cast<int>(s.integer("vehicles", l.vehicles, 1, 10'000'000));
  l.spacing_m = s.number("spacing_m", l.spacing_m, 1e-3, 1e4);
  l.altitude_layers = static_cast<int>(s.integer("altitude_layers", l.altitude_layers, 1, 1000));
  l.layer_spacing_m = s.number("layer_spacing_m", l.layer_spacing_m, 0.0, 1e4);
  l.ns_prefix = s.text("namespace_prefix", l.ns_prefix);
  if (std::string err = sim::validate_namespace(l.ns_prefix + "0"); !err.empty()) {
    s.fail("namespace_prefix", "got '" + l.ns_prefix + "': " + err);
  }
  spec.threads = static_cast<int>(s.integer("threads", spec.threads, 1, 64));
  int index = 0;
  for (const YAML::Node& n : s.sequence("record_vehicles")) {
    const std::string where = "record_vehicles[" + std::to_string(index++) + "]";
    long long v = -1;
    s.refuse_quoted_number(where, n);
    try {
      v = n.as<long long>();
    } catch (const YAML::Exception&) {
      s.fail(where, "got '" + (n.IsScalar() ? n.Scalar() : std::string("(not a scalar)")) +
                        "', expected a vehicle index (an integer)");
    }
    if (v < 0 || v >= l.vehicles) {
      s.fail(where,
             "got " + std::to_string(v) + ", expected a vehicle index in [0, " + std::to_string(l.vehicles - 1) + "]");
    }
    spec.record_vehicles.push_back(static_cast<int>(v));
  }
  s.reject_unknown_keys();
}

Scenario read_scenario(YamlSection root, const std::string& path, const model::VehicleParams* controller_vehicle);

}  // namespace

const char* to_string(CriteriaSet set) { return set == CriteriaSet::kSpec ? "spec" : "paper"; }

const char* to_string(Judge judge) {
  switch (judge) {
    case Judge::kSpec: return "spec";
    case Judge::kPaper: return "paper";
    case Judge::kNone: return "none";
  }
  return "?";
}

const std::vector<std::string>& judge_names() {
  static const std::vector<std::string> names = {"spec", "paper", "none"};
  return names;
}

std::optional<Judge> parse_judge(const std::string& name) {
  for (Judge j : {Judge::kSpec, Judge::kPaper, Judge::kNone}) {
    if (name == to_string(j)) return j;
  }
  return std::nullopt;
}

bool has_criteria(const Scenario& sc, CriteriaSet set) {
  const auto any = [&](const std::vector<Criterion>& criteria) {
    return std::any_of(criteria.begin(), criteria.end(), [&](const Criterion& c) { return c.set == set; });
  };
  return std::any_of(sc.steps.begin(), sc.steps.end(), [&](const StepSpec& s) { return any(s.criteria); }) ||
         (sc.hold && any(sc.hold->criteria)) || (sc.limits && any(sc.limits->criteria)) ||
         (sc.tracking && any(sc.tracking->criteria));
}

const std::vector<std::string>& hold_figure_names() {
  static const std::vector<std::string> names = {"max_horizontal_error_m", "rms_horizontal_error_m",
                                                 "max_vertical_error_m"};
  return names;
}

model::State initial_state(const Scenario& sc) {
  return model::Quadrotor(sc.vehicle).initial_state(sc.initial.p_W, sc.initial.yaw_rad, sc.initial.hover);
}

Scenario load_scenario(const std::string& path) { return read_scenario(YamlSection::load_file(path), path, nullptr); }

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
    if (c.firmware != "ardupilot") {
      throw std::invalid_argument("got '" + text +
                                  "', expected sitl:ardupilot or sitl:ardupilot:BINARY (docs/sitl.md)");
    }
    if (colon != std::string::npos) c.target = existing_file(text, rest.substr(colon + 1));
  } else if (text == "python") {
    c.kind = ControllerChoice::Kind::kPython;  // the class is named by the caller (controller.python)
  } else {
    if (!controllers::find_controller_type(text)) {
      std::vector<std::string> types;
      for (const auto& t : controllers::controller_types()) types.emplace_back(t.name);
      throw std::invalid_argument(
          "got '" + text + "', expected a controller type (" + controllers::controller_type_names() +
          "), python:MODULE:CLASS (a class written in Python), fmu:PATH (an FMU) or sitl:ardupilot[:BINARY] (a "
          "firmware's SITL build)" +
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
  // A SITL firmware flies what the file says of it (its sitl: section: parameters, mission) when it has one.
  const bool same =
      choice.kind == ControllerChoice::Kind::kType   ? !was_python && !was_fmu && !was_sitl && was_type == choice.target
      : choice.kind == ControllerChoice::Kind::kSitl ? was_sitl
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

Scenario defaults_flown_by(const std::string& controller) {
  Scenario sc;
  if (!controller.empty()) {
    if (parse_controller_choice(controller).kind == ControllerChoice::Kind::kType) {
      sc.controller = controllers::make_config(controller, sc.vehicle);
    } else {
      YAML::Node root(YAML::NodeType::Map);
      set_controller_type(root, controller);
      sc = load_scenario(root, "--controller");
    }
  }
  sc.name = "defaults";
  return sc;
}

Scenario load_scenario(const std::string& path, const std::string& controller_type) {
  if (controller_type.empty()) return load_scenario(path);
  YamlSection file = YamlSection::load_file(path);
  YAML::Node root = YAML::Clone(file.node());
  set_controller_type(root, controller_type);
  return read_scenario(YamlSection(root, path, ""), path, nullptr);
}

Scenario load_scenario(const YAML::Node& node, const std::string& path,
                       const model::VehicleParams* controller_vehicle) {
  if (!node.IsMap()) throw ConfigError(path + ": expected a mapping of keys at the top level");
  return read_scenario(YamlSection(node, path, ""), path, controller_vehicle);
}

namespace {
Scenario read_scenario(YamlSection root, const std::string& path, const model::VehicleParams* controller_vehicle) {
  Scenario sc;
  sc.path = path;
  sc.name = root.text("name", std::filesystem::path(path).stem().string());
  sc.description = root.text("description", "");
  if (auto v = root.section("vehicle")) read_vehicle(*v, sc.vehicle);

  double duration_s = 15.0;
  if (auto s = root.section("simulation")) {
    read_simulation(*s, sc.simulation, duration_s);
  } else {
    sc.simulation.duration_ticks = 1500;
  }

  if (std::string err =
          model::validate_step(sc.vehicle, sc.simulation.plant.clock.period_s(), sc.simulation.plant.substeps);
      !err.empty()) {
    root.fail("simulation.substeps", err);
  }

  if (auto f = root.section("message_faults")) read_faults(*f, sc.simulation, sc.simulation.faults);

  if (auto i = root.section("initial")) {
    const auto p = i->numbers("position_m", {0.0, 0.0, 0.0}, 3);
    sc.initial.p_W = {p[0], p[1], p[2]};
    if (sc.initial.p_W.z() < 0.0) i->fail("position_m", "z must be >= 0 (the ground is z = 0)");
    sc.initial.yaw_rad = i->number("yaw_rad", 0.0, -10.0, 10.0);
    sc.initial.hover = i->boolean("hover", false);
    i->reject_unknown_keys();
  }
  const model::VehicleParams& believed = controller_vehicle ? *controller_vehicle : sc.vehicle;
  if (auto c = root.section("controller")) {
    sc.controller = read_controller(*c, believed, std::filesystem::path(path).parent_path(), &sc.controller_fmu);
  } else {
    sc.controller = controllers::make_config(controllers::kDefaultControllerType, believed);
  }
  read_schedule(root, sc, duration_s);
  read_realism(root, sc);
  if (std::string err = controller_sensors_error(sc); !err.empty()) root.fail("controller.fmu", err);
  if (auto p = root.section("plant")) {
    sc.plant_fmu = read_fmu_spec(*p, std::filesystem::path(path).parent_path());
    p->reject_unknown_keys();
    sc.simulation.plant.external = make_plant_fmu(*p, *sc.plant_fmu);
    if (std::string key = sim::external_plant_conflict(sc.simulation.plant.realism, sc.vehicle); !key.empty()) {
      root.fail(key, "acts inside quadcosim's own plant model only, not with plant: {fmu: ...}");
    }
  }
  if (auto a = root.section("analysis")) read_steps(*a, sc, duration_s);
  if (auto w = root.section("swarm")) read_swarm(*w, sc.swarm.emplace());
  if (auto t = root.section("trajectory")) {
    sc.trajectory_spec = read_trajectory_spec(*t, std::filesystem::path(path).parent_path());
    if (sc.trajectory_spec) sc.controller.trajectory = trajectory::make_trajectory(*sc.trajectory_spec);
  }
  if (sc.controller.trajectory && !sc.tracking) sc.tracking.emplace();  // figures without criteria
  if (sc.tracking) {
    sc.tracking->reference_period_s = sc.simulation.plant.clock.period_s() * sc.simulation.controller_divider;
  }
  root.reject_unknown_keys();
  return sc;
}
}  // namespace

model::VehicleParams load_vehicle(const std::string& path) {
  YamlSection root = YamlSection::load_file(path);
  model::VehicleParams v;
  read_vehicle(root, v);
  return v;
}

control::ControllerConfig load_controller(const std::string& path, const model::VehicleParams& vehicle) {
  YamlSection root = YamlSection::load_file(path);
  return read_controller(root, vehicle, std::filesystem::path(path).parent_path(), nullptr);
}

namespace {
// A section holding only `fmu: <path>`, for the CLI's --fmu (its errors then read "<source>: fmu: ...").
YAML::Node fmu_node(const FmuSpec& spec) {
  YAML::Node n(YAML::NodeType::Map);
  n["fmu"] = spec.path;
  return n;
}
}  // namespace

void set_python_controller_factory(PythonControllerFactory factory) {
  const std::lock_guard lock(python_factory_mutex);
  python_factory = std::move(factory);
}

void use_plant_fmu(Scenario& sc, const FmuSpec& spec, const std::string& source) {
  YamlSection s(fmu_node(spec), source, "");
  sc.simulation.plant.external = make_plant_fmu(s, spec);
  sc.plant_fmu = spec;
  if (std::string key = sim::external_plant_conflict(sc.simulation.plant.realism, sc.vehicle); !key.empty()) {
    throw ConfigError((sc.path.empty() ? std::string("scenario") : sc.path) + ": " + key +
                      ": acts inside quadcosim's own plant model only, not with " + source + " " + spec.path);
  }
}

void use_controller_fmu(Scenario& sc, const FmuSpec& spec, const std::string& source) {
  YamlSection s(fmu_node(spec), source, "");
  control::ControllerConfig c;
  c.vehicle = sc.controller.vehicle;
  c.node = sc.controller.node;
  c.trajectory = sc.controller.trajectory;
  c.trajectory_offset_W = sc.controller.trajectory_offset_W;
  c.controller = make_controller_fmu(s, spec, c.vehicle);
  sc.controller = std::move(c);
  if (std::string err = controller_sensors_error(sc); !err.empty()) s.fail("fmu", err);
  sc.controller_fmu = spec;
}

}  // namespace quadcosim::io
