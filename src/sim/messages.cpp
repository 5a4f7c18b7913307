#include "sim/messages.hpp"

#include <array>
#include <bit>
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
  // By hand, back to front, two digits per division, straight into the label's own storage: the label
  // is written on every control step (std::to_chars + a std::string assignment cost several times
  // more in callgrind).
  const bool negative = stamp_ns < 0;
  std::uint64_t v = negative ? 0 - static_cast<std::uint64_t>(stamp_ns) : static_cast<std::uint64_t>(stamp_ns);
  // Decimal digits of v: log10 from the bit width (1233 / 4096 ~ log10(2)), corrected by one compare.
  static constexpr auto kPow10 = [] {
    std::array<std::uint64_t, 20> t{};
    t[0] = 1;
    for (std::size_t i = 1; i < t.size(); ++i) t[i] = t[i - 1] * 10;
    return t;
  }();
  const auto log10 = static_cast<std::size_t>((std::bit_width(v) * 1233) >> 12);
  const std::size_t digits = v == 0 ? 1 : log10 + 1 - (v < kPow10[log10] ? 1 : 0);
  label.resize(kLabelPrefix.size() + (negative ? 1 : 0) + digits);
  char* p = label.data() + label.size();
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
  std::memcpy(label.data(), kLabelPrefix.data(), kLabelPrefix.size());
}

namespace {
/// The value of 8 ASCII decimal digits at p, or -1 if any byte is not a digit: the 8 bytes as one
/// little-endian word, checked and combined a pair, a quad, then all eight at a time (SWAR).
std::int64_t eight_digits(const char* p) {
  std::uint64_t w;
  std::memcpy(&w, p, 8);
  // Each byte 0x30..0x39: high nibble 3, low nibble + 6 without a carry into the high nibble.
  if ((w & 0xF0F0F0F0F0F0F0F0ULL) != 0x3030303030303030ULL ||
      ((w & 0x0F0F0F0F0F0F0F0FULL) + 0x0606060606060606ULL) & 0xF0F0F0F0F0F0F0F0ULL) {
    return -1;
  }
  w &= 0x0F0F0F0F0F0F0F0FULL;                           // digits d0 (first, lowest byte) .. d7
  w = (w * 10 + (w >> 8)) & 0x00FF00FF00FF00FFULL;      // pairs: 10 d0 + d1, ...
  w = (w * 100 + (w >> 16)) & 0x0000FFFF0000FFFFULL;    // quads
  w = (w * 10000 + (w >> 32)) & 0x00000000FFFFFFFFULL;  // all eight
  return static_cast<std::int64_t>(w);
}
}  // namespace

std::string_view command_level_name(const Float64MultiArray& m) {
  for (const MultiArrayDimension& d : m.dim) {
    if (d.label.size() >= kCommandLevelPrefix.size() &&
        d.label.compare(0, kCommandLevelPrefix.size(), kCommandLevelPrefix) == 0) {
      return std::string_view(d.label).substr(kCommandLevelPrefix.size());
    }
  }
  return {};
}

void set_command_level(Float64MultiArray& m, std::string_view name) {
  const bool stamped = !m.dim.empty() && m.dim[0].label.compare(0, kLabelPrefix.size(), kLabelPrefix) == 0;
  const std::size_t at = stamped ? 1 : 0;
  if (name.empty() || name == "rotor_speeds") {
    if (m.dim.size() > at) m.dim.resize(at);
    return;
  }
  if (m.dim.size() <= at) m.dim.resize(at + 1);
  MultiArrayDimension& d = m.dim[at];
  d.label.assign(kCommandLevelPrefix);
  d.label.append(name);
  d.size = static_cast<std::uint32_t>(m.data.size());
  d.stride = d.size;
}

std::int64_t command_stamp_ns(const Float64MultiArray& m) {
  // The lockstep label alone, or followed by a level (set_command_level).
  if (m.dim.empty() || (m.dim.size() == 2 ? command_level_name(m).empty() : m.dim.size() != 1)) return -1;
  const std::string& l = m.dim[0].label;
  if (l.size() <= kLabelPrefix.size() || l.compare(0, kLabelPrefix.size(), kLabelPrefix) != 0) return -1;
  std::size_t digits = l.size() - kLabelPrefix.size();
  const char* c = l.data() + kLabelPrefix.size();
  std::int64_t v = 0;
  if constexpr (std::endian::native == std::endian::little) {
    // Eight digits at a time while no overflow is possible (up to 16 digits: < 1e16).
    while (digits >= 8 && v < 100'000'000) {
      const std::int64_t e = eight_digits(c);
      if (e < 0) return -1;
      v = v * 100'000'000 + e;
      c += 8;
      digits -= 8;
    }
  }
  for (std::size_t i = 0; i < digits; ++i) {
    const int d = c[i] - '0';
    if (d < 0 || d > 9 || v > (INT64_MAX - d) / 10) return -1;
    v = v * 10 + d;
  }
  return v;
}

}  // namespace quadcosim::msg
