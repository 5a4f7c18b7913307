// The keys a sweep varies, by their YAML path in the scenario (docs/sweeps.md, "Keys"): a path's
// canonical spelling, the scenario keys a --vary KEY resolves to (vehicle fields and their aliases,
// controller parameters, any number in the file), and reading and setting a number at a path.
// Internal to the sweep library; set_key and vehicle_aliases are declared in plan.hpp.
#pragma once

#include <yaml-cpp/yaml.h>

#include <string>
#include <vector>

#include "io/scenario.hpp"
#include "sweep/plan.hpp"

namespace quadcosim::sweep {

/// The one spelling of a key path ("initial.position_m.z", "initial.position_m[2]" and
/// "initial.position_m.2" are all "initial.position_m[2]").
std::string canonical_path(const std::string& path);

/// The scenario keys the KEY of `v` sets, in the scenario `nominal` parsed as `root`. Throws
/// std::invalid_argument naming the key when it names nothing the scenario has.
std::vector<Key> resolve(const Vary& v, const io::Scenario& nominal, const YAML::Node& root);

}  // namespace quadcosim::sweep
