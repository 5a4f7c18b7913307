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

#include "sim/messages.hpp"

namespace quadcosim::dds {

/// A double as `ros2 topic echo` shows it: Python's repr through PyYAML ("0.0", "1.5", "1.0e-05",
/// "1.0e+16", ".nan", ".inf", "-.inf").
std::string yaml_float(double v);

/// A string as PyYAML writes a scalar: plain when it reads back as the same string ("world"),
/// otherwise quoted ("''" for empty, "'123'", "'true'").
std::string yaml_string(std::string_view s);

/// One message in the block style of `ros2 topic echo`, fields in message order, each line ending
/// in '\n' (without the "---" separator).
std::string to_yaml(const msg::PoseStamped& m);
std::string to_yaml(const msg::TwistStamped& m);
std::string to_yaml(const msg::Imu& m);
std::string to_yaml(const msg::Float64MultiArray& m);
std::string to_yaml(const msg::Clock& m);
std::string to_yaml(const msg::ControllerStatus& m);
std::string to_yaml(const msg::PlantStatus& m);

/// Inter-arrival statistics over the last `window` intervals, as `ros2 topic hz` computes them.
class RateWindow {
 public:
  struct Stats {
    double rate_hz = 0;    ///< 1 / mean interval
    double min_s = 0, max_s = 0;
    double std_dev_s = 0;  ///< population standard deviation of the intervals
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
