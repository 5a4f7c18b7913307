// What `quadcosim topic echo` and `quadcosim topic hz` compute, kept free of DDS so it is testable:
// messages as the YAML `ros2 topic echo` prints (PyYAML block style, Python float repr), and the
// inter-arrival statistics of `ros2 topic hz`.
#pragma once

#include <cstddef>
#include <cstdint>
#include <deque>
#include <optional>
#include <string>
#include <string_view>
#include <type_traits>

#include "sim/messages.hpp"

namespace quadcosim::dds {

/// A double as `ros2 topic echo` shows it: Python's repr through PyYAML ("0.0", "1.5", "1.0e-05",
/// "1.0e+16", ".nan", ".inf", "-.inf").
std::string yaml_float(double v);

/// A string as PyYAML writes a scalar: plain when it reads back as the same string ("world"),
/// otherwise quoted ("''" for empty, "'123'", "'true'").
std::string yaml_string(std::string_view s);

/// Writes fields() lists (sim/messages.hpp) as `ros2 topic echo` does, in PyYAML's block style:
/// "key: value" per primitive or string; a nested message or group as "key:" over its fields indented
/// two spaces more; a fixed array or sequence as "key:" over one "- " line per element at the key's
/// own indentation ("key: []" when empty), an element that is a message having its first field after
/// the "- " and the others aligned with it. Integers in decimal (uint64 in full), doubles by
/// yaml_float, bools true/false, strings by yaml_string.
class YamlFields {
 public:
  YamlFields(std::string& out, int level) : out_(out), level_(level) {}

  template <class T>
  void field(std::string_view name, const T& v, msg::FieldNote = {}) {
    if constexpr (msg::IsArray<T>::value || msg::IsVector<T>::value) {
      if (v.empty()) {
        line(name, "[]");
        return;
      }
      line(name, {});
      for (const auto& e : v) element(e);
    } else if constexpr (std::is_arithmetic_v<T> || std::is_same_v<T, std::string>) {
      line(name, scalar(v));
    } else {
      line(name, {});
      YamlFields sub(out_, level_ + 1);
      T::fields(v, sub);
    }
  }
  template <class F>
  void group(std::string_view name, std::string_view /*ros_type*/, F&& visit) {
    line(name, {});
    YamlFields sub(out_, level_ + 1);
    visit(sub);
  }

 private:
  template <class E>
  void element(const E& e) {
    static_assert(!msg::IsArray<E>::value && !msg::IsVector<E>::value, "ROS has no arrays of arrays");
    if constexpr (std::is_arithmetic_v<E> || std::is_same_v<E, std::string>) {
      indent(level_);
      out_.append("- ").append(scalar(e)).append("\n");
    } else {
      // The mapping one level in, then "- " over the indentation of its first line.
      const std::size_t at = out_.size() + 2 * static_cast<std::size_t>(level_);
      YamlFields sub(out_, level_ + 1);
      E::fields(e, sub);
      out_.replace(at, 2, "- ");
    }
  }
  // "key: value", or "key:" alone when `value` is empty.
  void line(std::string_view key, std::string_view value) {
    indent(level_);
    out_.append(key).append(":");
    if (!value.empty()) out_.append(" ").append(value);
    out_.append("\n");
  }
  void indent(int level) { out_.append(2 * static_cast<std::size_t>(level), ' '); }

  static std::string scalar(bool v) { return v ? "true" : "false"; }
  static std::string scalar(double v) { return yaml_float(v); }
  static std::string scalar(const std::string& v) { return yaml_string(v); }
  template <class I, class = std::enable_if_t<std::is_integral_v<I>>>
  static std::string scalar(I v) {
    return std::to_string(v);
  }

  std::string& out_;
  int level_;
};

/// One message in the block style of `ros2 topic echo` (YamlFields over M::fields), each line ending
/// in '\n' (without the "---" separator).
template <class M>
std::string to_yaml(const M& m) {
  std::string out;
  YamlFields y(out, 0);
  M::fields(m, y);
  return out;
}

/// Inter-arrival statistics over the last `window` intervals, as `ros2 topic hz` computes them.
class RateWindow {
 public:
  struct Stats {
    double rate_hz = 0;  ///< 1 / mean interval
    double min_s = 0, max_s = 0;
    double std_dev_s = 0;    ///< population standard deviation of the intervals
    std::size_t window = 0;  ///< intervals used
  };

  explicit RateWindow(std::size_t window = 10000) : window_(window < 1 ? 1 : window) {}
  /// One message arrived at `t_ns` (any monotonic clock). A time before the previous one restarts.
  void add(std::int64_t t_ns);
  /// Nullopt until two messages have arrived.
  std::optional<Stats> stats() const;
  std::uint64_t messages() const { return messages_; }

 private:
  std::size_t window_;
  std::deque<std::int64_t> intervals_;
  std::int64_t last_ns_ = 0;
  std::uint64_t messages_ = 0;
};

/// "average rate: 100.003\n\tmin: 0.009s max: 0.011s std dev: 0.00021s window: 100\n"
std::string format_rate(const RateWindow::Stats& s);

}  // namespace quadcosim::dds
