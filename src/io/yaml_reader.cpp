#include "io/yaml_reader.hpp"

#include <fmt/format.h>

#include <cmath>
#include <filesystem>
#include <sstream>

#include "io/scenario_limits.hpp"
#include "util/did_you_mean.hpp"

namespace quadcosim::io {

YamlSection::YamlSection(YAML::Node node, std::string file, std::string path)
    : node_(std::move(node)), file_(std::move(file)), path_(std::move(path)) {}

YamlSection YamlSection::load_file(const std::string& file) {
  // Before parsing: a file of tens of megabytes parses into gigabytes of nodes.
  if (const Limits& l = limits(); l.enabled) {
    std::error_code ec;
    const std::uintmax_t size = std::filesystem::file_size(file, ec);
    if (!ec && size > l.scenario_bytes) {
      throw ConfigError(fmt::format("{}: the file is {} bytes, more than the {} a scenario file may have ({})", file,
                                    size, l.scenario_bytes, limit_hint("scenario_bytes")));
    }
  }
  YAML::Node root;
  try {
    root = YAML::LoadFile(file);
  } catch (const YAML::BadFile&) {
    throw ConfigError(file + ": cannot open the file");
  } catch (const YAML::Exception& e) {
    throw ConfigError(file + ": line " + std::to_string(e.mark.line + 1) + ": YAML syntax error: " + e.msg);
  }
  if (!root.IsMap()) throw ConfigError(file + ": expected a mapping of keys at the top level");
  return YamlSection(root, file, "");
}

std::string YamlSection::key_path(const std::string& key) const {
  if (key.empty()) return path_;
  return path_.empty() ? key : path_ + "." + key;
}

void YamlSection::fail(const std::string& key, const std::string& message) const {
  const std::string where = key_path(key);
  throw ConfigError(file_ + ": " + (where.empty() ? "" : where + ": ") + message);
}

std::string YamlSection::shown(const YAML::Node& n) const { return describe(n); }

std::string YamlSection::describe(const YAML::Node& n) {
  if (n.IsScalar()) return "'" + n.Scalar() + "'";
  if (n.IsSequence()) return "a list";
  if (n.IsMap()) return "a mapping";
  return "nothing";
}

std::pair<std::optional<double>, std::optional<double>> YamlSection::bounds(const std::string& key) {
  const YAML::Node b = get(key);
  if (!b.IsSequence() || b.size() != 2) fail(key, "expected [min, max] (null for no bound)");
  std::optional<double> bound[2];
  for (int i = 0; i < 2; ++i) {
    if (b[i].IsNull()) continue;
    refuse_quoted_number(key, b[i]);
    try {
      bound[i] = b[i].as<double>();
    } catch (const YAML::Exception&) {
      fail(key, "got " + describe(b[i]) + ", expected a number or null");
    }
  }
  if (bound[0] && bound[1] && *bound[0] > *bound[1]) fail(key, "min is above max");
  return {bound[0], bound[1]};
}

bool YamlSection::has(const std::string& key) const {
  asked_.insert(key);
  return node_[key].IsDefined();
}

bool YamlSection::written_as_text(const YAML::Node& n) {
  // yaml-cpp tags a quoted (or block) scalar "!" and a plain one "?"; nodes built in code have none.
  return n.IsScalar() && (n.Tag() == "!" || n.Tag() == "tag:yaml.org,2002:str");
}

void YamlSection::refuse_quoted_number(const std::string& key, const YAML::Node& n) const {
  double unused = 0.0;
  if (written_as_text(n) && YAML::convert<double>::decode(n, unused)) {
    fail(key, "\"" + n.Scalar() + "\" is a string; write " + n.Scalar() + " without quotes");
  }
}

YAML::Node YamlSection::get(const std::string& key) {
  used_.insert(key);
  return node_[key];
}

YAML::Node YamlSection::raw(const std::string& key) { return get(key); }

double YamlSection::number(const std::string& key, double fallback, double min, double max) {
  return number(key, fallback, model::Range{min, max});
}

double YamlSection::number(const std::string& key, double fallback, const model::Range& range) {
  const YAML::Node n = get(key);
  if (!n.IsDefined()) return fallback;
  const std::string expected = "expected a number in " + range.text();
  refuse_quoted_number(key, n);
  double v = 0.0;
  try {
    if (!n.IsScalar()) throw YAML::Exception(n.Mark(), "");
    v = n.as<double>();
  } catch (const YAML::Exception&) {
    fail(key, "got " + shown(n) + ", " + expected);
  }
  if (!range.contains(v)) fail(key, "got " + shown(n) + ", " + expected);
  return v;
}

long long YamlSection::integer(const std::string& key, long long fallback, long long min, long long max) {
  const YAML::Node n = get(key);
  if (!n.IsDefined()) return fallback;
  const std::string expected = "expected a whole number in [" + std::to_string(min) + ", " + std::to_string(max) + "]";
  refuse_quoted_number(key, n);
  long long v = 0;
  try {
    if (!n.IsScalar()) throw YAML::Exception(n.Mark(), "");
    v = n.as<long long>();
  } catch (const YAML::Exception&) {
    fail(key, "got " + shown(n) + ", " + expected);
  }
  if (v < min || v > max) fail(key, "got " + shown(n) + ", " + expected);
  return v;
}

bool YamlSection::boolean(const std::string& key, bool fallback) {
  const YAML::Node n = get(key);
  if (!n.IsDefined()) return fallback;
  if (bool unused = false; written_as_text(n) && YAML::convert<bool>::decode(n, unused)) {
    fail(key, "\"" + n.Scalar() + "\" is a string; write " + n.Scalar() + " without quotes");
  }
  try {
    if (!n.IsScalar()) throw YAML::Exception(n.Mark(), "");
    return n.as<bool>();
  } catch (const YAML::Exception&) {
    fail(key, "got " + shown(n) + ", expected true or false");
  }
}

std::string YamlSection::text(const std::string& key, const std::string& fallback) {
  const YAML::Node n = get(key);
  if (!n.IsDefined()) return fallback;
  if (!n.IsScalar()) fail(key, "got " + shown(n) + ", expected text");
  return n.Scalar();
}

std::string YamlSection::choice(const std::string& key, const std::string& fallback,
                                const std::vector<std::string>& choices) {
  const YAML::Node n = get(key);
  if (!n.IsDefined()) return fallback;
  std::string expected = "expected one of";
  for (const auto& c : choices) expected += " '" + c + "'";
  if (n.IsScalar()) {
    for (const auto& c : choices) {
      if (n.Scalar() == c) return c;
    }
    fail(key, "got " + shown(n) + ", " + expected + util::did_you_mean(n.Scalar(), choices));
  }
  fail(key, "got " + shown(n) + ", " + expected);
}

std::vector<double> YamlSection::numbers(const std::string& key, std::vector<double> fallback, std::size_t count) {
  const YAML::Node n = get(key);
  if (!n.IsDefined()) return fallback;
  const std::string expected = "expected a list of " + std::to_string(count) + " numbers";
  if (!n.IsSequence() || n.size() != count) fail(key, "got " + shown(n) + ", " + expected);
  std::vector<double> out;
  for (const auto& e : n) {
    refuse_quoted_number(key, e);
    double v = 0.0;
    try {
      if (!e.IsScalar()) throw YAML::Exception(e.Mark(), "");
      v = e.as<double>();
    } catch (const YAML::Exception&) {
      fail(key, "got an entry " + shown(e) + ", " + expected);
    }
    if (!std::isfinite(v)) fail(key, "got an entry " + shown(e) + ", " + expected + " (finite)");
    out.push_back(v);
  }
  return out;
}

std::optional<YamlSection> YamlSection::section(const std::string& key) {
  const YAML::Node n = get(key);
  if (!n.IsDefined() || n.IsNull()) return std::nullopt;
  if (!n.IsMap()) fail(key, "got " + shown(n) + ", expected a mapping of keys");
  return YamlSection(n, file_, key_path(key));
}

std::vector<YAML::Node> YamlSection::sequence(const std::string& key) {
  const YAML::Node n = get(key);
  if (!n.IsDefined() || n.IsNull()) return {};
  if (!n.IsSequence()) fail(key, "got " + shown(n) + ", expected a list");
  return {n.begin(), n.end()};
}

std::string YamlSection::key_text(const YAML::Node& key) const {
  // YAML allows a list or a mapping as a key (`? [a, b]: 1`); no key of ours is one.
  if (!key.IsScalar()) fail("", "got " + shown(key) + " as a key, expected a plain name");
  return key.Scalar();
}

std::vector<std::string> YamlSection::keys() {
  std::vector<std::string> out;
  for (const auto& kv : node_) {
    out.push_back(key_text(kv.first));
    used_.insert(out.back());
  }
  return out;
}

void YamlSection::reject_unknown_keys() const {
  for (const auto& kv : node_) {
    const std::string key = key_text(kv.first);
    if (used_.count(key)) continue;
    std::vector<std::string> known(used_.begin(), used_.end());
    known.insert(known.end(), asked_.begin(), asked_.end());
    fail(key, "unknown key" + util::did_you_mean(key, known));
  }
}

}  // namespace quadcosim::io
