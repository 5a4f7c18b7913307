// What a sweep varies and how each run's values are drawn (docs/sweeps.md).
//
// A --vary spec names a scenario key by its YAML path (controller.altitude.kp, vehicle.mass_kg,
// initial.position_m[2], environment.gusts.w20_m_s, schedule[0].set.z_des, ...) or one of the short
// aliases of the vehicle (mass, inertia, kt, ...), and a distribution:
//   KEY=P%                 uniform factor in [1 - P/100, 1 + P/100] on the nominal value
//   KEY=uniform(a,b)       uniform in [a, b]
//   KEY=normal(mu,sigma)   normal, truncated to the key's declared range (none declared: untruncated)
//   KEY=grid(v1,v2,...)    every listed value (full factorial over the grid keys)
//   KEY=linspace(a,b,n)    n values evenly spaced from a to b, as a grid
// Run i's values are a pure function of (sweep seed, i, key): neither threads nor shards change them.
// Each run's scenario is the scenario file's parsed YAML with the run's values set in it, loaded and
// validated as that file would be; the controller keeps the nominal vehicle (it was designed for it).
#pragma once

#include <yaml-cpp/yaml.h>

#include <cstdint>
#include <map>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "io/scenario.hpp"

namespace quadcosim::sweep {

/// Bad --vary spec, sampler or shard: what() names the spec and what was expected.
class PlanError : public std::invalid_argument {
 public:
  using std::invalid_argument::invalid_argument;
};

enum class Distribution { kPercent, kUniform, kNormal, kGrid };
enum class Sampler { kRandom, kLhs };

/// The inclusive range a key declares (controller parameter table, ...), with where it comes from.
struct DeclaredRange {
  double min = 0.0, max = 0.0;
  std::string source;
};

/// One scenario key a spec sets.
struct Key {
  std::string path;               ///< YAML path, e.g. "vehicle.mass_kg"
  std::string stream;             ///< name of its random stream (a vehicle field's own name, else the path)
  std::optional<double> nominal;  ///< value in the scenario (file or default), when known
  std::optional<DeclaredRange> declared;
  bool is_vehicle = false;  ///< the plant flies it; the controller keeps the nominal value
};

struct Vary {
  std::string spec;  ///< as typed
  std::string name;  ///< the KEY part as typed
  Distribution distribution = Distribution::kPercent;
  double a = 0.0, b = 0.0;     ///< percent: P/100; uniform: [a, b]; normal: mu, sigma
  std::vector<double> values;  ///< grid values
  std::vector<Key> keys;       ///< an alias may stand for several keys, each drawn on its own
};

/// Parses the syntax of one spec ("mass=10%", "controller.altitude.kp=grid(2,4,8)"): name,
/// distribution and numbers; keys are resolved by make_plan. Throws PlanError naming the spec.
Vary parse_vary(const std::string& spec);

struct Plan {
  std::string scenario_file;  ///< as recorded in the header and each run's metrics.json
  /// The path the loader takes the scenario to be at: relative paths in it (a Python controller's
  /// module, an FMU, a trajectory file) are found from its folder. scenario_file, unless the sweep
  /// is continued elsewhere (`--resume`, `sweep rerun`: the folder the sweep recorded).
  std::string scenario_source;
  YAML::Node root;  ///< the scenario file as parsed (never modified)
  io::Scenario nominal;
  std::uint64_t seed = 1;
  Sampler sampler = Sampler::kRandom;
  std::vector<Vary> vary;
  int repeats = 1;                                     ///< runs per grid point
  std::vector<int> grid_sizes;                         ///< one per grid spec, in order (the first varies slowest)
  int runs = 0;                                        ///< product of grid_sizes times repeats
  std::map<std::string, std::vector<int>> lhs_strata;  ///< per random key: run -> stratum
  io::Judge judge = io::Judge::kSpec;                  ///< the criteria set each run is judged against (--judge)
  /// What the scenario's FMUs and Python classes are made by, for the nominal and each run's scenario
  /// (scenario_for) and for the runs' provenance.
  io::ScenarioResolvers resolvers;
};

/// Loads the scenario, resolves every spec's keys (refusing unknown keys, keys varied twice, a
/// relative spread on a key whose nominal value is unknown, bounds outside a declared range) and
/// checks each grid value by loading the scenario with it. `runs_per_point` is the number of runs
/// (no grid) or of runs per grid point. Throws PlanError or io::ConfigError.
/// With `scenario_source` non-empty, the file is read from `scenario_file` but loaded as if it were
/// at `scenario_source` (Plan::scenario_source). The plan keeps `resolvers` (Plan::resolvers).
Plan make_plan(const std::string& scenario_file, const std::vector<std::string>& specs, std::uint64_t seed,
               int runs_per_point, Sampler sampler, const io::ScenarioResolvers& resolvers,
               const std::string& scenario_source = "");

/// The draws of one run.
struct Sample {
  int index = 0;
  std::uint64_t seed = 0;                              ///< the run's seed (noise, gusts)
  std::vector<std::pair<std::string, double>> values;  ///< key path -> value, in spec order
  std::map<std::string, double> factors;               ///< KEY=P% keys: stream name -> factor
};

/// Run `index`'s seed and values: a pure function of (plan.seed, index, key).
Sample sample(const Plan& plan, int index);

/// The scenario run `index` flies: its values set in the parsed file and loaded from there; the
/// vehicle is the plant's, controller.params.vehicle the nominal one. Throws io::ConfigError naming
/// the key and value when the loader refuses a value.
io::Scenario scenario_for(const Plan& plan, const Sample& sample);

/// Sets `value` at `path` in `root` (creating absent mappings); throws PlanError when the path
/// crosses a value that is not a mapping or list, or indexes past a list's end.
void set_key(YAML::Node root, const std::string& path, double value,
             const std::map<std::string, std::vector<double>>& default_lists = {});

/// The aliases of today's vehicle keys ("mass" -> vehicle.mass_kg, "inertia" -> the three axes, ...).
const std::map<std::string, std::vector<std::string>>& vehicle_aliases();

/// "uniform", "lhs".
std::string to_string(Sampler s);
std::string to_string(Distribution d);

}  // namespace quadcosim::sweep
