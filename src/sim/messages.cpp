#include "sim/messages.hpp"

#include <cstdint>

namespace quadcosim::msg {

Time Time::from_ns(std::int64_t ns) {
  std::int64_t sec = ns / 1'000'000'000;
  std::int64_t rem = ns % 1'000'000'000;
  if (rem < 0) {
    rem += 1'000'000'000;
    --sec;
  }
  return {static_cast<std::int32_t>(sec), static_cast<std::uint32_t>(rem)};
}

std::string command_label(std::int64_t stamp_ns) { return "rotors@" + std::to_string(stamp_ns); }

std::int64_t command_stamp_ns(const Float64MultiArray& m) {
  if (m.dim.size() != 1) return -1;
  const std::string& l = m.dim[0].label;
  constexpr std::string_view prefix = "rotors@";
  if (l.size() <= prefix.size() || l.compare(0, prefix.size(), prefix) != 0) return -1;
  std::int64_t v = 0;
  for (std::size_t i = prefix.size(); i < l.size(); ++i) {
    if (l[i] < '0' || l[i] > '9' || v > (INT64_MAX - 9) / 10) return -1;
    v = v * 10 + (l[i] - '0');
  }
  return v;
}

}  // namespace quadcosim::msg
