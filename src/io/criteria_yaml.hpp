// The pass bands of an analysis block (docs/scenarios.md, "Criteria: spec and paper"): `spec:`, the
// bounds a good controller must meet, and `paper:`, the paper's controller's measured response. The
// old `criteria:` is read as `spec:`, so files written before the two sets existed still load.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "io/scenario.hpp"
#include "io/yaml_reader.hpp"

namespace quadcosim::io {

/// The bands of `block` (a step, the hold, the tracking): `spec:` and `paper:`, each a mapping
/// figure: [min, max] with null for an absent bound; `criteria:` read as `spec:`. `known` lists the
/// figures the block has and `what` names them in an error ("step figure"). Throws ConfigError for
/// `criteria:` beside `spec:` (naming both keys), an unknown figure, a band that is not [min, max].
/// Spec criteria first, then paper, each in file order; nothing when the block has none of the keys.
std::optional<std::vector<Criterion>> read_criteria_sets(YamlSection& block, const std::vector<std::string>& known,
                                                         const std::string& what);

/// "a, b or c".
std::string or_list(const std::vector<std::string>& names);

}  // namespace quadcosim::io
