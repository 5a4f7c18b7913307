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
      if (c == '\n')
        out += "\\n";
      else if (c == '\t')
        out += "\\t";
      else if (c == '"')
        out += "\\\"";
      else if (c == '\\')
        out += "\\\\";
      else if (c < 0x20 || c == 0x7f) {
        char x[8];
        std::snprintf(x, sizeof x, "\\x%02X", c);
        out += x;
      } else
        out += static_cast<char>(c);
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
