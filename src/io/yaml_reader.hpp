// A thin checked view of a YAML mapping: every read names file and key path in its error, keys
// nobody asked for are reported as unknown with the nearest known one (catches typos such as
// `mas_kg`), and a number or boolean written in quotes (`mass_kg: "1.2"`) is refused: YAML makes it
// text, and taking text for a number would hide a value some other reader takes as text.
#pragma once

#include <yaml-cpp/yaml.h>

#include <optional>
#include <set>
#include <string>
#include <utility>
#include <vector>

#include "io/scenario.hpp"
#include "model/vehicle_params.hpp"

namespace quadcosim::io {

class YamlSection {
 public:
  YamlSection(YAML::Node node, std::string file, std::string path);

  /// Parses `file`; throws ConfigError when it cannot be read or parsed or is not a mapping.
  static YamlSection load_file(const std::string& file);

  bool has(const std::string& key) const;
  /// A number in [min, max] (NaN/inf refused); `fallback` when the key is absent.
  double number(const std::string& key, double fallback, double min, double max);
  /// A number inside `range` (its ends open or closed; NaN/inf refused); `fallback` when absent.
  double number(const std::string& key, double fallback, const model::Range& range);
  /// An integer in [min, max]; `fallback` when absent.
  long long integer(const std::string& key, long long fallback, long long min, long long max);
  bool boolean(const std::string& key, bool fallback);
  std::string text(const std::string& key, const std::string& fallback);
  /// One of `choices`; `fallback` when absent.
  std::string choice(const std::string& key, const std::string& fallback, const std::vector<std::string>& choices);
  /// A list of exactly n numbers; `fallback` when absent.
  std::vector<double> numbers(const std::string& key, std::vector<double> fallback, std::size_t n);
  /// A pass band `[min, max]` under `key`, null for an absent bound; throws ConfigError when it is not
  /// a two-element list of numbers or nulls, or when min is above max.
  std::pair<std::optional<double>, std::optional<double>> bounds(const std::string& key);
  /// The mapping under `key`, or nothing when absent.
  std::optional<YamlSection> section(const std::string& key);
  /// The sequence under `key` as raw nodes (empty when absent); throws when not a sequence.
  std::vector<YAML::Node> sequence(const std::string& key);
  /// Raw access for callers that walk the mapping themselves (marks the key as used).
  YAML::Node raw(const std::string& key);
  /// All keys, in file order (marks them used).
  std::vector<std::string> keys();

  /// Throws ConfigError at `key` when `n` is a number written in quotes ("1.2" is a string; write 1.2
  /// without quotes); for readers that take numbers from raw nodes.
  void refuse_quoted_number(const std::string& key, const YAML::Node& n) const;
  /// True for a scalar written in quotes or tagged !!str: YAML's text, whatever it spells.
  static bool written_as_text(const YAML::Node& n);

  /// Throws ConfigError naming the first key that no read asked for, and the asked-for key nearest
  /// to it when one is close.
  void reject_unknown_keys() const;

  /// "file: path.key: message".
  [[noreturn]] void fail(const std::string& key, const std::string& message) const;
  std::string key_path(const std::string& key) const;
  const std::string& file() const { return file_; }
  const YAML::Node& node() const { return node_; }
  /// How a value appears in messages: 'text' for a scalar, else "a list", "a mapping", "nothing".
  static std::string describe(const YAML::Node& n);

 private:
  YAML::Node get(const std::string& key);
  std::string shown(const YAML::Node& n) const;
  std::string key_text(const YAML::Node& key) const;

  YAML::Node node_;
  std::string file_;
  std::string path_;
  std::set<std::string> used_;
  /// Keys asked about by has() (known names too, for "did you mean").
  mutable std::set<std::string> asked_;
};

}  // namespace quadcosim::io
