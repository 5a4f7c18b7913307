#include "io/scenario.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <map>
#include <string_view>

#include "analysis/step_metrics.hpp"
#include "analysis/tracking.hpp"
#include "io/controller_yaml.hpp"
#include "io/criteria_yaml.hpp"
#include "io/realism_yaml.hpp"
#include "io/scenario_limits.hpp"
#include "io/sitl_yaml.hpp"
#include "io/trajectory_yaml.hpp"
#include "io/vehicle_yaml.hpp"
#include "io/yaml_reader.hpp"
#include "sim/topics.hpp"

namespace quadcosim::io {

namespace {

constexpr double kHuge = 1e12;

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
LimitsSpec read_limits(YamlSection& limits, double duration_s, int rotors) {
  LimitsSpec spec;
  const auto read_set = [&](YamlSection& l, CriteriaSet set) {
    auto bound = [&](const std::string& key, double hi, const std::vector<std::string>& figures) {
      if (!l.has(key)) return;
      const double v = l.number(key, 0.0, 0.0, hi);
      for (const auto& f : figures) spec.criteria.push_back(Criterion{f, std::nullopt, v, set});
    };
    bound("max_saturated_s", duration_s, {"saturated_s"});
    std::vector<std::string> per_rotor;  // one bound per rotor of the vehicle
    for (int k = 1; k <= rotors; ++k) per_rotor.push_back("rotor" + std::to_string(k) + "_saturated_s");
    bound("max_rotor_saturated_s", duration_s, per_rotor);
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
  if (auto l = analysis.section("limits")) sc.limits = read_limits(*l, duration_s, sc.vehicle.rotor_count);
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

Scenario read_scenario(YamlSection root, const std::string& path, const ScenarioResolvers& resolvers,
                       const model::VehicleParams* controller_vehicle);

}  // namespace

const std::vector<std::string>& hold_figure_names() {
  static const std::vector<std::string> names = {"max_horizontal_error_m", "rms_horizontal_error_m",
                                                 "max_vertical_error_m"};
  return names;
}

model::State initial_state(const Scenario& sc) {
  return model::Quadrotor(sc.vehicle).initial_state(sc.initial.p_W, sc.initial.yaw_rad, sc.initial.hover);
}

Scenario load_scenario(const std::string& path, const ScenarioResolvers& resolvers) {
  return read_scenario(YamlSection::load_file(path), path, resolvers, nullptr);
}

Scenario defaults_flown_by(const std::string& controller, const ScenarioResolvers& resolvers) {
  Scenario sc;
  if (!controller.empty()) {
    if (parse_controller_choice(controller).kind == ControllerChoice::Kind::kType) {
      sc.controller = controllers::make_config(controller, sc.vehicle);
    } else {
      YAML::Node root(YAML::NodeType::Map);
      set_controller_type(root, controller);
      sc = load_scenario(root, "--controller", resolvers);
    }
  }
  sc.name = "defaults";
  return sc;
}

Scenario load_scenario(const std::string& path, const std::string& controller_type,
                       const ScenarioResolvers& resolvers) {
  if (controller_type.empty()) return load_scenario(path, resolvers);
  YamlSection file = YamlSection::load_file(path);
  YAML::Node root = YAML::Clone(file.node());
  set_controller_type(root, controller_type);
  return read_scenario(YamlSection(root, path, ""), path, resolvers, nullptr);
}

Scenario load_scenario(const YAML::Node& node, const std::string& path, const ScenarioResolvers& resolvers,
                       const model::VehicleParams* controller_vehicle) {
  if (!node.IsMap()) throw ConfigError(path + ": expected a mapping of keys at the top level");
  return read_scenario(YamlSection(node, path, ""), path, resolvers, controller_vehicle);
}

namespace {
Scenario read_scenario(YamlSection root, const std::string& path, const ScenarioResolvers& resolvers,
                       const model::VehicleParams* controller_vehicle) {
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
    sc.controller =
        read_controller(*c, believed, std::filesystem::path(path).parent_path(), &sc.controller_fmu, resolvers);
  } else {
    sc.controller = controllers::make_config(controllers::kDefaultControllerType, believed);
  }
  read_schedule(root, sc, duration_s);
  // PX4 flies on the magnetometer, barometer and GNSS: what the file lacks of them is added first.
  std::vector<std::string> added =
      add_px4_sensors(root, 1.0 / sc.simulation.plant.clock.period_s(), sc.simulation.controller_divider);
  read_realism(root, sc);
  sc.controller.controller =
      with_px4_site(sc.controller.controller, sc.simulation.plant.realism.extra_sensors, std::move(added));
  if (std::string err = controller_sensors_error(sc, resolvers); !err.empty()) root.fail("controller.fmu", err);
  if (auto p = root.section("plant")) {
    sc.plant_fmu = read_fmu_spec(*p, std::filesystem::path(path).parent_path());
    p->reject_unknown_keys();
    sc.simulation.plant.external = make_plant_fmu(*p, *sc.plant_fmu, resolvers);
    if (std::string err = sc.simulation.plant.external->check(sc.vehicle); !err.empty()) p->fail("fmu", err);
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

control::ControllerConfig load_controller(const std::string& path, const model::VehicleParams& vehicle,
                                          const ScenarioResolvers& resolvers) {
  YamlSection root = YamlSection::load_file(path);
  return read_controller(root, vehicle, std::filesystem::path(path).parent_path(), nullptr, resolvers);
}

namespace {
// A section holding only `fmu: <path>`, for the CLI's --fmu (its errors then read "<source>: fmu: ...").
YAML::Node fmu_node(const FmuSpec& spec) {
  YAML::Node n(YAML::NodeType::Map);
  n["fmu"] = spec.path;
  return n;
}
}  // namespace

void use_plant_fmu(Scenario& sc, const FmuSpec& spec, const std::string& source, const ScenarioResolvers& resolvers) {
  YamlSection s(fmu_node(spec), source, "");
  sc.simulation.plant.external = make_plant_fmu(s, spec, resolvers);
  if (std::string err = sc.simulation.plant.external->check(sc.vehicle); !err.empty()) s.fail("fmu", err);
  sc.plant_fmu = spec;
  if (std::string key = sim::external_plant_conflict(sc.simulation.plant.realism, sc.vehicle); !key.empty()) {
    throw ConfigError((sc.path.empty() ? std::string("scenario") : sc.path) + ": " + key +
                      ": acts inside quadcosim's own plant model only, not with " + source + " " + spec.path);
  }
}

void use_controller_fmu(Scenario& sc, const FmuSpec& spec, const std::string& source,
                        const ScenarioResolvers& resolvers) {
  YamlSection s(fmu_node(spec), source, "");
  control::ControllerConfig c;
  c.vehicle = sc.controller.vehicle;
  c.node = sc.controller.node;
  c.trajectory = sc.controller.trajectory;
  c.trajectory_offset_W = sc.controller.trajectory_offset_W;
  c.controller = make_controller_fmu(s, spec, c.vehicle, resolvers);
  sc.controller = std::move(c);
  if (std::string err = controller_sensors_error(sc, resolvers); !err.empty()) s.fail("fmu", err);
  sc.controller_fmu = spec;
}

}  // namespace quadcosim::io
