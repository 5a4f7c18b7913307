// A histogram of non-negative integer samples (durations in ns) in fixed memory, for figures gathered
// over runs of any length (the lockstep round trip of a plant running for hours): percentiles within
// 1/64 (1.6 %) of the sample, exact count, minimum and maximum. Buckets: one per value below 64, then
// 64 per power of two (log-linear, as HDR histograms are), 3,776 counters in all.
#pragma once

#include <algorithm>
#include <array>
#include <bit>
#include <cstddef>
#include <cstdint>
#include <limits>

namespace quadcosim::util {

class LogHistogram {
 public:
  static constexpr int kSubBits = 6;  ///< 2^6 = 64 buckets per power of two
  static constexpr std::size_t kBuckets = (64 - kSubBits + 1) << kSubBits;

  /// Counts `v` (negative values count as 0).
  void record(std::int64_t v) {
    const std::uint64_t u = v < 0 ? 0 : static_cast<std::uint64_t>(v);
    ++counts_[index(u)];
    ++count_;
    min_ = std::min(min_, u);
    max_ = std::max(max_, u);
  }

  std::uint64_t count() const { return count_; }
  bool empty() const { return count_ == 0; }
  /// The largest and smallest sample, exactly (0 when empty).
  std::int64_t max() const { return static_cast<std::int64_t>(max_); }
  std::int64_t min() const { return empty() ? 0 : static_cast<std::int64_t>(min_); }

  /// The sample at rank floor(q (n - 1)) of the sorted samples (numpy's "lower", as
  /// analysis::percentile_lower), to within its bucket: the bucket's lower edge, at most 1/64 below
  /// the sample, never below the minimum; q = 1 gives the maximum exactly. 0 when empty.
  std::int64_t percentile_lower(double q) const {
    if (count_ == 0) return 0;
    if (q >= 1.0) return max();
    const auto rank = static_cast<std::uint64_t>(std::max(0.0, q) * static_cast<double>(count_ - 1));
    std::uint64_t seen = 0;
    for (std::size_t i = 0; i < kBuckets; ++i) {
      seen += counts_[i];
      if (seen > rank) return static_cast<std::int64_t>(std::clamp(lower_edge(i), min_, max_));
    }
    return max();
  }

  /// The bucket of `u` and the smallest value of bucket `i` (for tests).
  static std::size_t index(std::uint64_t u) {
    if (u < (1u << kSubBits)) return static_cast<std::size_t>(u);
    const int e = std::bit_width(u) - 1;  // >= kSubBits
    const std::uint64_t sub = (u >> (e - kSubBits)) & ((1u << kSubBits) - 1);
    return (static_cast<std::size_t>(e - kSubBits + 1) << kSubBits) + static_cast<std::size_t>(sub);
  }
  static std::uint64_t lower_edge(std::size_t i) {
    if (i < (1u << kSubBits)) return i;
    const int e = static_cast<int>(i >> kSubBits) + kSubBits - 1;
    const std::uint64_t sub = i & ((1u << kSubBits) - 1);
    return (std::uint64_t{1} << e) | (sub << (e - kSubBits));
  }

 private:
  std::array<std::uint64_t, kBuckets> counts_{};
  std::uint64_t count_ = 0;
  std::uint64_t min_ = std::numeric_limits<std::uint64_t>::max();
  std::uint64_t max_ = 0;
};

}  // namespace quadcosim::util
