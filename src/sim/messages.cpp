#include "sim/messages.hpp"

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

void write_command_label(std::string& label, std::int64_t stamp_ns) {
  // Digits by hand, back to front: the label is written on every control step, and this is several
  // times cheaper than std::to_chars + parsing in callgrind.
  char buf[kLabelPrefix.size() + 21];
  char* end = buf + sizeof buf;
  char* p = end;
  const bool negative = stamp_ns < 0;
  std::uint64_t v = negative ? 0 - static_cast<std::uint64_t>(stamp_ns) : static_cast<std::uint64_t>(stamp_ns);
  do {
    *--p = static_cast<char>('0' + v % 10);
    v /= 10;
  } while (v != 0);
  if (negative) *--p = '-';
  p -= kLabelPrefix.size();
  std::memcpy(p, kLabelPrefix.data(), kLabelPrefix.size());
  label.assign(p, static_cast<std::size_t>(end - p));
}

std::int64_t command_stamp_ns(const Float64MultiArray& m) {
  if (m.dim.size() != 1) return -1;
  const std::string& l = m.dim[0].label;
  if (l.size() <= kLabelPrefix.size() || l.compare(0, kLabelPrefix.size(), kLabelPrefix) != 0) return -1;
  std::int64_t v = 0;
  for (std::size_t i = kLabelPrefix.size(); i < l.size(); ++i) {
    if (l[i] < '0' || l[i] > '9' || v > (INT64_MAX - 9) / 10) return -1;
    v = v * 10 + (l[i] - '0');
  }
  return v;
}

}  // namespace quadcosim::msg
