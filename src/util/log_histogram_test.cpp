// LogHistogram against the exact percentiles of the same samples (analysis::percentile_lower on the
// sorted vector): every bucket edge, random durations over nine decades, and the fixed memory.
#include "util/log_histogram.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>
#include <vector>

#include "analysis/percentile.hpp"

namespace quadcosim::util {
namespace {

using analysis::percentile_lower;

TEST(LogHistogram, BucketsCoverEveryValueInOrderWithinOneSixtyFourth) {
  // Each value falls in the bucket whose lower edge is the largest edge not above it.
  for (std::uint64_t u :
       {0ull, 1ull, 63ull, 64ull, 65ull, 127ull, 128ull, 1000ull, 123456789ull, (1ull << 40) + 12345ull, ~0ull >> 1}) {
    const std::size_t i = LogHistogram::index(u);
    ASSERT_LT(i, LogHistogram::kBuckets) << u;
    EXPECT_LE(LogHistogram::lower_edge(i), u) << u;
    if (i + 1 < LogHistogram::kBuckets) {
      EXPECT_GT(LogHistogram::lower_edge(i + 1), u) << u;
    }
    EXPECT_LE(static_cast<double>(u - LogHistogram::lower_edge(i)), static_cast<double>(u) / 64.0) << u;
  }
  for (std::size_t i = 1; i < LogHistogram::kBuckets; ++i) {
    ASSERT_GT(LogHistogram::lower_edge(i), LogHistogram::lower_edge(i - 1)) << i;
    ASSERT_EQ(LogHistogram::index(LogHistogram::lower_edge(i)), i) << i;
  }
}

TEST(LogHistogram, PercentilesAgreeWithTheSortedSamples) {
  std::mt19937_64 rng(42);
  std::lognormal_distribution<double> dist(std::log(80'000.0), 1.5);  // round trips around 80 us
  std::vector<std::int64_t> samples;
  LogHistogram h;
  for (int i = 0; i < 100'000; ++i) {
    const auto v = static_cast<std::int64_t>(dist(rng));
    samples.push_back(v);
    h.record(v);
  }
  std::sort(samples.begin(), samples.end());
  EXPECT_EQ(h.count(), samples.size());
  EXPECT_EQ(h.max(), samples.back());
  EXPECT_EQ(h.min(), samples.front());
  EXPECT_EQ(h.percentile_lower(1.0), samples.back());
  for (double q : {0.0, 0.01, 0.25, 0.5, 0.9, 0.99, 0.999}) {
    const auto exact = static_cast<double>(percentile_lower(samples, q));
    const auto approx = static_cast<double>(h.percentile_lower(q));
    EXPECT_LE(approx, exact) << q;
    EXPECT_GE(approx, exact * (1.0 - 1.0 / 64.0)) << q;
  }
}

TEST(LogHistogram, SmallValuesAreExactAndNegativesCountAsZero) {
  LogHistogram h;
  EXPECT_TRUE(h.empty());
  EXPECT_EQ(h.percentile_lower(0.5), 0);
  for (int v : {5, 3, 9, -4}) h.record(v);
  EXPECT_EQ(h.count(), 4u);
  EXPECT_EQ(h.min(), 0);
  EXPECT_EQ(h.percentile_lower(0.0), 0);
  EXPECT_EQ(h.percentile_lower(0.5), 3);  // sorted 0 3 5 9: rank floor(0.5 * 3) = 1
  EXPECT_EQ(h.percentile_lower(1.0), 9);
  EXPECT_EQ(sizeof(LogHistogram), LogHistogram::kBuckets * 8 + 3 * 8);  // fixed, whatever the count
}

}  // namespace
}  // namespace quadcosim::util
