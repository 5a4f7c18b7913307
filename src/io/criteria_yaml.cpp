#include "io/criteria_yaml.hpp"

#include <algorithm>

#include "util/did_you_mean.hpp"

namespace quadcosim::io {

std::string or_list(const std::vector<std::string>& names) {
  std::string text;
  for (std::size_t i = 0; i < names.size(); ++i) {
    text += (i == 0 ? "" : i + 1 == names.size() ? " or " : ", ") + names[i];
  }
  return text;
}

std::optional<std::vector<Criterion>> read_criteria_sets(YamlSection& block, const std::vector<std::string>& known,
                                                         const std::string& what) {
  // `criteria` is the old name of `spec`: both at once would leave one of them unread, so say which.
  if (block.has("criteria") && block.has("spec")) {
    block.fail("criteria",
               "given beside spec; criteria is the old name of spec (the bounds a good controller must meet): keep "
               "one of the two keys");
  }
  std::optional<std::vector<Criterion>> out;
  const auto read = [&](const std::string& key, CriteriaSet set) {
    auto bands = block.section(key);
    if (!bands) return;
    if (!out) out.emplace();
    for (const std::string& fig : bands->keys()) {
      if (std::find(known.begin(), known.end(), fig) == known.end()) {
        bands->fail(fig, "unknown " + what + " (expected " + or_list(known) + ")" + util::did_you_mean(fig, known));
      }
      const auto [min, max] = bands->bounds(fig);
      out->push_back(Criterion{fig, min, max, set});
    }
  };
  read(block.has("criteria") ? "criteria" : "spec", CriteriaSet::kSpec);
  read("paper", CriteriaSet::kPaper);
  return out;
}

}  // namespace quadcosim::io
