#include "sim/messages.hpp"

#include <array>
#include <cstdint>
#include <cstring>

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

namespace {
constexpr std::string_view kLabelPrefix = "rotors@";
}  // namespace

std::string command_label(std::int64_t stamp_ns) {
  std::string label;
  write_command_label(label, stamp_ns);
  return label;
}

namespace {
// "00" "01" ... "99": the label's digits are written two at a time.
constexpr auto kDigitPairs = [] {
  std::array<char, 200> t{};
  for (int i = 0; i < 100; ++i) {
    t[static_cast<std::size_t>(2 * i)] = static_cast<char>('0' + i / 10);
    t[static_cast<std::size_t>(2 * i + 1)] = static_cast<char>('0' + i % 10);
  }
  return t;
}();
}  // namespace

void write_command_label(std::string& label, std::int64_t stamp_ns) {
  // By hand, back to front, two digits per division: the label is written on every control step
  // (std::to_chars + a std::string assignment cost several times more in callgrind).
  char buf[kLabelPrefix.size() + 21];
  char* end = buf + sizeof buf;
  char* p = end;
  const bool negative = stamp_ns < 0;
  std::uint64_t v = negative ? 0 - static_cast<std::uint64_t>(stamp_ns) : static_cast<std::uint64_t>(stamp_ns);
  while (v >= 100) {
    const std::size_t pair = 2 * static_cast<std::size_t>(v % 100);
    v /= 100;
    *--p = kDigitPairs[pair + 1];
    *--p = kDigitPairs[pair];
  }
  if (v >= 10) {
    *--p = kDigitPairs[2 * v + 1];
    *--p = kDigitPairs[2 * v];
  } else {
    *--p = static_cast<char>('0' + v);
  }
  if (negative) *--p = '-';
  p -= kLabelPrefix.size();
  std::memcpy(p, kLabelPrefix.data(), kLabelPrefix.size());
  label.assign(p, static_cast<std::size_t>(end - p));
}

std::int64_t command_stamp_ns(const Float64MultiArray& m) {
  if (m.dim.size() != 1) return -1;
  const std::string& l = m.dim[0].label;
  if (l.size() <= kLabelPrefix.size() || l.compare(0, kLabelPrefix.size(), kLabelPrefix) != 0) return -1;
  const std::size_t digits = l.size() - kLabelPrefix.size();
  const char* c = l.data() + kLabelPrefix.size();
  // Up to 18 digits cannot overflow an int64 (< 9.3e18): no range check per digit.
  std::int64_t v = 0;
  if (digits <= 18) {
    for (std::size_t i = 0; i < digits; ++i) {
      const unsigned d = static_cast<unsigned char>(c[i]) - unsigned{'0'};
      if (d > 9) return -1;
      v = v * 10 + d;
    }
    return v;
  }
  for (std::size_t i = 0; i < digits; ++i) {
    const int d = c[i] - '0';
    if (d < 0 || d > 9 || v > (INT64_MAX - d) / 10) return -1;
    v = v * 10 + d;
  }
  return v;
}

}  // namespace quadcosim::msg
