#include "sweep/plan.hpp"

#include "sweep/key_paths.hpp"

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

Plan make_plan(const std::string& scenario_file, const std::vector<std::string>& specs, std::uint64_t seed,
               int runs_per_point, Sampler sampler, const io::ScenarioResolvers& resolvers,
               const std::string& scenario_source) {
  Plan p;
  p.resolvers = resolvers;
  p.scenario_file = scenario_file;
  p.scenario_source = scenario_source.empty() ? scenario_file : scenario_source;
  if (scenario_source.empty()) {
    p.nominal = io::load_scenario(scenario_file, resolvers);
    p.root = YAML::LoadFile(scenario_file);  // load_scenario has read it: it parses
  } else {
    try {
      p.root = YAML::LoadFile(scenario_file);
    } catch (const YAML::Exception& e) {
      throw io::ConfigError(scenario_file + ": " + e.what());
    }
    if (!p.root.IsMap()) throw io::ConfigError(scenario_file + ": expected a mapping of scenario sections");
    p.nominal = io::load_scenario(p.root, p.scenario_source, resolvers);
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
      (void)io::load_scenario(root, p.scenario_source, resolvers);
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
    sc = io::load_scenario(root, plan.scenario_source, plan.resolvers,
                           &plan.nominal.vehicle);  // designed for the nominal vehicle
    sc.path = plan.scenario_file;
  }
  sc.simulation.plant.realism.seed = s.seed;
  return sc;
}

}  // namespace quadcosim::sweep
