#include "dds/topic_tools.hpp"

#include <charconv>
#include <cmath>
#include <cstdio>
#include <regex>

namespace quadcosim::dds {

std::string yaml_float(double v) {
  if (std::isnan(v)) return ".nan";
  if (std::isinf(v)) return v > 0 ? ".inf" : "-.inf";
  // Shortest round-trip digits, as Python's repr, then Python's choice of notation: positional for
  // decimal exponents -4..15, scientific otherwise (with at least two exponent digits).
  char buf[64];
  const auto r = std::to_chars(buf, buf + sizeof buf, v, std::chars_format::scientific);
  const std::string sci(buf, r.ptr);  // "-1.2345e-05"
  const auto e_at = sci.find('e');
  const bool negative = sci[0] == '-';
  std::string digits;
  for (std::size_t i = negative ? 1 : 0; i < e_at; ++i) {
    if (sci[i] != '.') digits += sci[i];
  }
  const int exponent = std::stoi(sci.substr(e_at + 1));
  std::string out = negative ? "-" : "";
  if (exponent >= -4 && exponent < 16) {
    if (exponent >= 0) {
      const auto int_len = static_cast<std::size_t>(exponent) + 1;
      if (digits.size() <= int_len) {
        out += digits + std::string(int_len - digits.size(), '0') + ".0";
      } else {
        out += digits.substr(0, int_len) + "." + digits.substr(int_len);
      }
    } else {
      out += "0." + std::string(static_cast<std::size_t>(-exponent - 1), '0') + digits;
    }
  } else {
    // Python: "1e-05", "1.5e+16"; PyYAML adds ".0" when there is no '.', so it reads back as a float.
    out += digits.substr(0, 1) + "." + (digits.size() > 1 ? digits.substr(1) : "0");
    char e[16];
    std::snprintf(e, sizeof e, "e%c%02d", exponent < 0 ? '-' : '+', std::abs(exponent));
    out += e;
  }
  return out;
}

std::string yaml_string(std::string_view s) {
  bool printable = true;
  for (unsigned char c : s) {
    if (c < 0x20 || c == 0x7f) printable = false;
  }
  if (!printable) {  // double quotes with escapes
    std::string out = "\"";
    for (unsigned char c : s) {
      if (c == '\n') out += "\\n";
      else if (c == '\t') out += "\\t";
      else if (c == '"') out += "\\\"";
      else if (c == '\\') out += "\\\\";
      else if (c < 0x20 || c == 0x7f) {
        char x[8];
        std::snprintf(x, sizeof x, "\\x%02X", c);
        out += x;
      }
      else out += static_cast<char>(c);
    }
    return out + "\"";
  }
  // Scalars that would read back as something else (bool, null, number, timestamp), or that start
  // with an indicator, or carry ": " / " #", are single-quoted, like PyYAML does.
  static const std::regex implicit(
      "(yes|Yes|YES|no|No|NO|true|True|TRUE|false|False|FALSE|on|On|ON|off|Off|OFF)"
      "|(~|null|Null|NULL)"
      "|([-+]?(0b[0-1_]+|0[0-7_]+|(0|[1-9][0-9_]*)|0x[0-9a-fA-F_]+|[1-9][0-9_]*(:[0-5]?[0-9])+))"
      "|([-+]?([0-9][0-9_]*)?\\.[0-9_]*([eE][-+][0-9]+)?|[-+]?[0-9][0-9_]*(:[0-5]?[0-9])+\\.[0-9_]*"
      "|[-+]?\\.(inf|Inf|INF)|\\.(nan|NaN|NAN))"
      "|([0-9]{4}-[0-9]{1,2}-[0-9]{1,2}.*)|<<|=");
  bool quote = s.empty() || s.front() == ' ' || s.back() == ' ' || s.back() == ':' ||
               s.find(": ") != std::string_view::npos || s.find(" #") != std::string_view::npos ||
               std::regex_match(s.begin(), s.end(), implicit);
  if (!quote) {
    const char c = s.front();
    if (std::string_view("#,[]{}&*!|>'\"%@`").find(c) != std::string_view::npos) quote = true;
    if ((c == '-' || c == '?' || c == ':') && (s.size() == 1 || s[1] == ' ')) quote = true;
  }
  if (!quote) return std::string(s);
  std::string out = "'";
  for (char c : s) {
    out += c;
    if (c == '\'') out += '\'';
  }
  return out + "'";
}

namespace {

// Block-style YAML, one line per call; `level` is the nesting depth (two spaces each).
class Yaml {
 public:
  Yaml& map(int level, std::string_view key) {
    indent(level);
    out_.append(key).append(":\n");
    return *this;
  }
  Yaml& value(int level, std::string_view key, const std::string& v) {
    indent(level);
    out_.append(key).append(": ").append(v).append("\n");
    return *this;
  }
  Yaml& value(int level, std::string_view key, double v) { return value(level, key, yaml_float(v)); }
  Yaml& value(int level, std::string_view key, std::int64_t v) { return value(level, key, std::to_string(v)); }
  Yaml& value(int level, std::string_view key, bool v) { return value(level, key, std::string(v ? "true" : "false")); }
  // A sequence under a key: PyYAML puts its "- " at the key's own indentation.
  template <class Range>
  Yaml& list(int level, std::string_view key, const Range& items) {
    if (std::begin(items) == std::end(items)) return value(level, key, std::string("[]"));
    map(level, key);
    for (const auto& v : items) {
      indent(level);
      out_ += "- " + scalar(v) + "\n";
    }
    return *this;
  }
  Yaml& time(int level, std::string_view key, const msg::Time& t) {
    map(level, key);
    value(level + 1, "sec", std::int64_t{t.sec});
    return value(level + 1, "nanosec", std::int64_t{t.nanosec});
  }
  Yaml& header(int level, const msg::Header& h) {
    map(level, "header");
    time(level + 1, "stamp", h.stamp);
    return value(level + 1, "frame_id", yaml_string(h.frame_id));
  }
  Yaml& vector3(int level, std::string_view key, const msg::Vector3& v) {
    map(level, key);
    value(level + 1, "x", v.x);
    value(level + 1, "y", v.y);
    return value(level + 1, "z", v.z);
  }
  Yaml& quaternion(int level, std::string_view key, const msg::Quaternion& q) {
    map(level, key);
    value(level + 1, "x", q.x);
    value(level + 1, "y", q.y);
    value(level + 1, "z", q.z);
    return value(level + 1, "w", q.w);
  }
  void raw(std::string_view text) { out_ += text; }
  void indent(int level) { out_.append(static_cast<std::size_t>(2 * level), ' '); }
  std::string str() && { return std::move(out_); }

 private:
  static std::string scalar(double v) { return yaml_float(v); }
  static std::string scalar(bool v) { return v ? "true" : "false"; }
  std::string out_;
};

}  // namespace

std::string to_yaml(const msg::PoseStamped& m) {
  Yaml y;
  y.header(0, m.header).map(0, "pose").vector3(1, "position", m.position).quaternion(1, "orientation", m.orientation);
  return std::move(y).str();
}

std::string to_yaml(const msg::TwistStamped& m) {
  Yaml y;
  y.header(0, m.header).map(0, "twist").vector3(1, "linear", m.linear).vector3(1, "angular", m.angular);
  return std::move(y).str();
}

std::string to_yaml(const msg::Imu& m) {
  Yaml y;
  y.header(0, m.header)
      .quaternion(0, "orientation", m.orientation)
      .list(0, "orientation_covariance", m.orientation_covariance)
      .vector3(0, "angular_velocity", m.angular_velocity)
      .list(0, "angular_velocity_covariance", m.angular_velocity_covariance)
      .vector3(0, "linear_acceleration", m.linear_acceleration)
      .list(0, "linear_acceleration_covariance", m.linear_acceleration_covariance);
  return std::move(y).str();
}

std::string to_yaml(const msg::Float64MultiArray& m) {
  Yaml y;
  y.map(0, "layout");
  if (m.dim.empty()) {
    y.value(1, "dim", std::string("[]"));
  } else {
    y.map(1, "dim");
    for (const auto& d : m.dim) {  // a sequence of mappings: "- " then the keys aligned after it
      y.indent(1);
      y.raw("- label: " + yaml_string(d.label) + "\n");
      y.value(2, "size", std::int64_t{d.size});
      y.value(2, "stride", std::int64_t{d.stride});
    }
  }
  y.value(1, "data_offset", std::int64_t{m.data_offset});
  y.list(0, "data", m.data);
  return std::move(y).str();
}

std::string to_yaml(const msg::Clock& m) {
  Yaml y;
  y.time(0, "clock", m.clock);
  return std::move(y).str();
}

std::string to_yaml(const msg::ControllerStatus& m) {
  Yaml y;
  y.header(0, m.header)
      .value(0, "mode", yaml_string(m.mode))
      .list(0, "setpoint", m.setpoint)
      .list(0, "u", m.u)
      .list(0, "error", m.error)
      .list(0, "rotor_saturated", m.rotor_saturated)
      .value(0, "tilt_saturated", m.tilt_saturated)
      .value(0, "safety", m.safety)
      .value(0, "rejected_non_finite", static_cast<std::int64_t>(m.rejected_non_finite))
      .value(0, "rejected_bad_quaternion", static_cast<std::int64_t>(m.rejected_bad_quaternion))
      .value(0, "rejected_bad_stamp", static_cast<std::int64_t>(m.rejected_bad_stamp))
      .value(0, "rejected_stamp_backwards", static_cast<std::int64_t>(m.rejected_stamp_backwards));
  return std::move(y).str();
}

std::string to_yaml(const msg::PlantStatus& m) {
  Yaml y;
  y.header(0, m.header)
      .value(0, "commands_accepted", static_cast<std::int64_t>(m.commands_accepted))
      .value(0, "commands_clamped", static_cast<std::int64_t>(m.commands_clamped))
      .value(0, "commands_rejected_length", static_cast<std::int64_t>(m.commands_rejected_length))
      .value(0, "commands_rejected_non_finite", static_cast<std::int64_t>(m.commands_rejected_non_finite))
      .value(0, "last_problem", yaml_string(m.last_problem));
  return std::move(y).str();
}

void RateWindow::add(std::int64_t t_ns) {
  if (messages_ > 0 && t_ns >= last_ns_) {
    intervals_.push_back(t_ns - last_ns_);
    if (intervals_.size() > window_) intervals_.pop_front();
  } else if (messages_ > 0) {
    intervals_.clear();  // time went backwards: start over, as ros2 topic hz does
  }
  last_ns_ = t_ns;
  ++messages_;
}

std::optional<RateWindow::Stats> RateWindow::stats() const {
  if (intervals_.empty()) return std::nullopt;
  Stats s;
  s.window = intervals_.size();
  double sum = 0;
  std::int64_t lo = intervals_.front(), hi = intervals_.front();
  for (std::int64_t d : intervals_) {
    sum += static_cast<double>(d);
    lo = std::min(lo, d);
    hi = std::max(hi, d);
  }
  const double mean = sum / static_cast<double>(s.window);
  double var = 0;
  for (std::int64_t d : intervals_) var += (static_cast<double>(d) - mean) * (static_cast<double>(d) - mean);
  var /= static_cast<double>(s.window);
  s.rate_hz = mean > 0 ? 1e9 / mean : 0.0;
  s.min_s = static_cast<double>(lo) / 1e9;
  s.max_s = static_cast<double>(hi) / 1e9;
  s.std_dev_s = std::sqrt(var) / 1e9;
  return s;
}

std::string format_rate(const RateWindow::Stats& s) {
  char buf[256];
  std::snprintf(buf, sizeof buf, "average rate: %.3f\n\tmin: %.3fs max: %.3fs std dev: %.5fs window: %zu\n", s.rate_hz,
                s.min_s, s.max_s, s.std_dev_s, s.window);
  return buf;
}

}  // namespace quadcosim::dds
