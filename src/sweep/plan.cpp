#include "sweep/plan.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>

#include "control/controller_config.hpp"
#include "control/parameters.hpp"
#include "controllers/registry.hpp"
#include "model/random.hpp"
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

double number(const std::string& spec, const std::string& text) {
  std::size_t b = text.find_first_not_of(' '), e = text.find_last_not_of(' ');
  const std::string t = b == std::string::npos ? "" : text.substr(b, e - b + 1);
  char* end = nullptr;
  const double v = std::strtod(t.c_str(), &end);
  if (t.empty() || end != t.c_str() + t.size() || !std::isfinite(v)) {
    throw PlanError("--vary " + spec + ": got '" + t + "', expected a finite number");
  }
  return v;
}

std::vector<double> arguments(const std::string& spec, const std::string& body) {
  std::vector<double> out;
  std::size_t start = 0;
  while (true) {
    const std::size_t comma = body.find(',', start);
    out.push_back(number(spec, body.substr(start, comma == std::string::npos ? std::string::npos : comma - start)));
    if (comma == std::string::npos) break;
    start = comma + 1;
  }
  return out;
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

std::map<std::string, std::vector<double>> default_lists(const io::Scenario& sc) {
  const auto v3 = [](const Eigen::Vector3d& v) { return std::vector<double>{v.x(), v.y(), v.z()}; };
  return {{"vehicle.aero.linear_drag_N_s_m", v3(sc.vehicle.aero.linear_drag_N_s_m)},
          {"vehicle.aero.quadratic_drag_N_s2_m2", v3(sc.vehicle.aero.quadratic_drag_N_s2_m2)},
          {"initial.position_m", v3(sc.initial.p_W)}};
}

// Standard normal CDF.
double phi(double x) { return 0.5 * std::erfc(-x / std::numbers::sqrt2); }

// The u-quantile of N(mu, sigma) truncated to [lo, hi], by bisection on the CDF (exact to the last
// bits, and the same numbers on every machine that has a correctly rounded erfc... and the same
// binary on one).
double truncated_normal(double mu, double sigma, double lo, double hi, double u) {
  const double zl = std::isfinite(lo) ? (lo - mu) / sigma : -40.0;
  const double zh = std::isfinite(hi) ? (hi - mu) / sigma : 40.0;
  const double pl = phi(std::max(zl, -40.0)), ph = phi(std::min(zh, 40.0));
  const double target = pl + u * (ph - pl);
  double a = std::max(zl, -40.0), b = std::min(zh, 40.0);
  for (int i = 0; i < 200 && a < b; ++i) {
    const double m = 0.5 * (a + b);
    if (m <= a || m >= b) break;
    (phi(m) < target ? a : b) = m;
  }
  return std::clamp(mu + sigma * 0.5 * (a + b), lo, hi);
}

void check_declared(const Vary& v, const Key& k, double value, const char* what) {
  if (!k.declared) return;
  if (value < k.declared->min || value > k.declared->max) {
    throw PlanError(fmt::format("--vary {}: {} {} = {:g} is outside the declared range [{:g}, {:g}] of {} ({})", v.spec,
                                what, k.path, value, k.declared->min, k.declared->max, k.path, k.declared->source));
  }
}

}  // namespace

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

std::string to_string(Sampler s) { return s == Sampler::kLhs ? "lhs" : "random"; }

std::string to_string(Distribution d) {
  switch (d) {
    case Distribution::kPercent: return "percent";
    case Distribution::kUniform: return "uniform";
    case Distribution::kNormal: return "normal";
    case Distribution::kGrid: return "grid";
  }
  return "?";
}

Vary parse_vary(const std::string& spec) {
  const auto eq = spec.find('=');
  const std::string expected =
      "expected KEY=P%, KEY=uniform(a,b), KEY=normal(mu,sigma), KEY=grid(v1,v2,...) or KEY=linspace(a,b,n) "
      "(e.g. mass=10%)";
  if (eq == std::string::npos || eq == 0) throw PlanError("--vary " + spec + ": " + expected);
  Vary v;
  v.spec = spec;
  v.name = spec.substr(0, eq);
  const std::string rhs = spec.substr(eq + 1);
  if (!rhs.empty() && rhs.back() == '%') {
    const std::string n = rhs.substr(0, rhs.size() - 1);
    char* end = nullptr;
    const double p = std::strtod(n.c_str(), &end);
    if (n.empty() || end != n.c_str() + n.size() || !std::isfinite(p) || p < 0.0 || p >= 100.0) {
      throw PlanError("--vary " + spec + ": got '" + n + "%', expected a percentage in [0, 100)");
    }
    v.distribution = Distribution::kPercent;
    v.a = p / 100.0;
    return v;
  }
  const auto open = rhs.find('(');
  if (open == std::string::npos || rhs.back() != ')') throw PlanError("--vary " + spec + ": " + expected);
  const std::string fn = rhs.substr(0, open);
  const std::vector<double> args = arguments(spec, rhs.substr(open + 1, rhs.size() - open - 2));
  const auto need = [&](std::size_t n, const char* form) {
    if (args.size() != n) {
      throw PlanError(fmt::format("--vary {}: {} takes {} numbers ({}), got {}", spec, fn, n, form, args.size()));
    }
  };
  if (fn == "uniform") {
    need(2, "a,b");
    if (!(args[0] < args[1])) throw PlanError("--vary " + spec + ": uniform(a,b) needs a < b");
    v.distribution = Distribution::kUniform;
    v.a = args[0];
    v.b = args[1];
  } else if (fn == "normal") {
    need(2, "mu,sigma");
    if (!(args[1] > 0.0)) throw PlanError("--vary " + spec + ": normal(mu,sigma) needs sigma > 0");
    v.distribution = Distribution::kNormal;
    v.a = args[0];
    v.b = args[1];
  } else if (fn == "grid") {
    v.distribution = Distribution::kGrid;
    v.values = args;
  } else if (fn == "linspace") {
    need(3, "a,b,n");
    const double n = args[2];
    if (n < 1 || n > 100000 || n != std::floor(n)) {
      throw PlanError(fmt::format("--vary {}: linspace(a,b,n) needs a whole n in [1, 100000], got {:g}", spec, n));
    }
    v.distribution = Distribution::kGrid;
    const int count = static_cast<int>(n);
    for (int i = 0; i < count; ++i) {
      // Ends exact: a at i = 0, b at i = n - 1.
      v.values.push_back(count == 1 ? args[0]
                                    : (i == count - 1 ? args[1] : args[0] + (args[1] - args[0]) * i / (count - 1)));
    }
  } else {
    throw PlanError("--vary " + spec + ": unknown distribution '" + fn + "'; " + expected);
  }
  return v;
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

Plan make_plan(const std::string& scenario_file, const std::vector<std::string>& specs, std::uint64_t seed,
               int runs_per_point, Sampler sampler, const std::string& scenario_source) {
  Plan p;
  p.scenario_file = scenario_file;
  p.scenario_source = scenario_source.empty() ? scenario_file : scenario_source;
  if (scenario_source.empty()) {
    p.nominal = io::load_scenario(scenario_file);
    p.root = YAML::LoadFile(scenario_file);  // load_scenario has read it: it parses
  } else {
    try {
      p.root = YAML::LoadFile(scenario_file);
    } catch (const YAML::Exception& e) {
      throw io::ConfigError(scenario_file + ": " + e.what());
    }
    if (!p.root.IsMap()) throw io::ConfigError(scenario_file + ": expected a mapping of scenario sections");
    p.nominal = io::load_scenario(p.root, p.scenario_source);
    p.nominal.path = scenario_file;
  }
  p.seed = seed;
  p.sampler = sampler;
  p.repeats = runs_per_point;
  if (runs_per_point < 1) throw PlanError("--runs must be at least 1");
  const auto lists = default_lists(p.nominal);
  std::map<std::string, std::string> used;  // canonical_path -> the key as the earlier --vary set it
  // Loads the scenario with `value` at every key of `v` (the check of a grid value or a typical one).
  const auto try_load = [&](const Vary& v, double value, const char* what) {
    YAML::Node root = YAML::Clone(p.root);
    for (const Key& k : v.keys) {
      check_declared(v, k, v.distribution == Distribution::kPercent ? *k.nominal * value : value, what);
      set_key(root, k.path, v.distribution == Distribution::kPercent ? *k.nominal * value : value, lists);
    }
    try {
      (void)io::load_scenario(root, p.scenario_source);
    } catch (const io::ConfigError& e) {
      throw PlanError(fmt::format("--vary {}: {} {:g} refused: {}", v.spec, what, value, e.what()));
    } catch (const std::invalid_argument& e) {
      throw PlanError(fmt::format("--vary {}: {} {:g} refused: {}", v.spec, what, value, e.what()));
    }
  };
  double runs = 1.0;
  for (const std::string& spec : specs) {
    Vary v = parse_vary(spec);
    v.keys = resolve(v, p.nominal, p.root);
    for (const Key& k : v.keys) {
      if (const auto [it, fresh] = used.emplace(canonical_path(k.path), k.path); !fresh) {
        throw PlanError("--vary " + spec + ": " + k.stream + " is already varied by an earlier --vary" +
                        (it->second == k.path ? std::string() : " (as " + it->second + ")"));
      }
      if (v.distribution == Distribution::kPercent && !k.nominal) {
        throw PlanError("--vary " + spec + ": " + k.path + " has no value in " + scenario_file +
                        " to vary relatively; write it there or use uniform(a,b), normal(mu,sigma) or grid(...)");
      }
    }
    switch (v.distribution) {
      case Distribution::kPercent:
        try_load(v, 1.0 - v.a, "factor");
        try_load(v, 1.0 + v.a, "factor");
        break;
      case Distribution::kUniform:
        try_load(v, v.a, "value");
        try_load(v, v.b, "value");
        break;
      case Distribution::kNormal: try_load(v, v.a, "mean"); break;
      case Distribution::kGrid:
        for (double x : v.values) try_load(v, x, "grid value");
        p.grid_sizes.push_back(static_cast<int>(v.values.size()));
        runs *= static_cast<double>(v.values.size());
        break;
    }
    p.vary.push_back(std::move(v));
  }
  runs *= runs_per_point;
  if (runs > 10'000'000) throw PlanError(fmt::format("the sweep would have {:g} runs; at most 10000000", runs));
  p.runs = static_cast<int>(runs);
  if (sampler == Sampler::kLhs) {
    for (const Vary& v : p.vary) {
      if (v.distribution == Distribution::kGrid) continue;
      for (const Key& k : v.keys) {
        // Stratum of each run: a permutation of 0..runs-1 (Fisher-Yates on the key's own stream).
        std::vector<int> perm(static_cast<std::size_t>(p.runs));
        for (int i = 0; i < p.runs; ++i) perm[static_cast<std::size_t>(i)] = i;
        model::Rng rng(model::stream_seed(seed, "lhs", k.stream));
        for (int i = p.runs - 1; i > 0; --i) {
          const auto j = static_cast<int>(rng.next_u64() % static_cast<std::uint64_t>(i + 1));
          std::swap(perm[static_cast<std::size_t>(i)], perm[static_cast<std::size_t>(j)]);
        }
        p.lhs_strata[k.path] = std::move(perm);
      }
    }
  }
  return p;
}

Sample sample(const Plan& plan, int index) {
  Sample s;
  s.index = index;
  s.seed = model::stream_seed(plan.seed, "sweep", "run/" + std::to_string(index));
  // Grid point of the run: index / repeats in mixed radix, the first grid spec slowest.
  int point = index / plan.repeats;
  std::vector<int> digit(plan.grid_sizes.size());
  for (std::size_t g = plan.grid_sizes.size(); g-- > 0;) {
    digit[g] = point % plan.grid_sizes[g];
    point /= plan.grid_sizes[g];
  }
  std::size_t grid = 0;
  for (const Vary& v : plan.vary) {
    if (v.distribution == Distribution::kGrid) {
      const double x = v.values[static_cast<std::size_t>(digit[grid++])];
      for (const Key& k : v.keys) s.values.emplace_back(k.path, x);
      continue;
    }
    for (const Key& k : v.keys) {
      model::Rng rng(model::stream_seed(s.seed, "vary", k.stream));
      double u = rng.uniform();
      if (const auto it = plan.lhs_strata.find(k.path); it != plan.lhs_strata.end()) {
        u = (static_cast<double>(it->second[static_cast<std::size_t>(index)]) + u) / static_cast<double>(plan.runs);
      }
      double x = 0.0;
      switch (v.distribution) {
        case Distribution::kPercent: {
          const double factor = 1.0 + v.a * (2.0 * u - 1.0);
          s.factors[k.stream] = factor;
          x = *k.nominal * factor;
          break;
        }
        case Distribution::kUniform: x = v.a + (v.b - v.a) * u; break;
        case Distribution::kNormal: {
          const double inf = std::numeric_limits<double>::infinity();
          x = truncated_normal(v.a, v.b, k.declared ? k.declared->min : -inf, k.declared ? k.declared->max : inf, u);
          break;
        }
        case Distribution::kGrid: break;
      }
      s.values.emplace_back(k.path, x);
    }
  }
  return s;
}

io::Scenario scenario_for(const Plan& plan, const Sample& s) {
  io::Scenario sc;
  if (s.values.empty()) {
    sc = plan.nominal;
  } else {
    YAML::Node root = YAML::Clone(plan.root);
    const auto lists = default_lists(plan.nominal);
    for (const auto& [path, value] : s.values) set_key(root, path, value, lists);
    sc = io::load_scenario(root, plan.scenario_source, &plan.nominal.vehicle);  // designed for the nominal vehicle
    sc.path = plan.scenario_file;
  }
  sc.simulation.plant.realism.seed = s.seed;
  return sc;
}

}  // namespace quadcosim::sweep
