// Percentiles of sorted samples, the two definitions the outputs use (each figure keeps its own).
#pragma once

#include <cstddef>
#include <vector>

namespace quadcosim::analysis {

/// Percentile q in [0, 1] of `sorted` (ascending, non-empty) by linear interpolation between the
/// closest ranks (numpy's default method, "linear"). The sweep statistics (summary.json, p5 .. p95).
double percentile_linear(const std::vector<double>& sorted, double q);

/// Percentile q in [0, 1] of `sorted` (ascending, non-empty): the sample at rank floor(q (n - 1)),
/// no interpolation (numpy's "lower"), so always a value that occurred. The timing figures (the
/// lockstep round trip, period jitter) and the swarm's final position error.
template <class T>
T percentile_lower(const std::vector<T>& sorted, double q) {
  return sorted[static_cast<std::size_t>(q * static_cast<double>(sorted.size() - 1))];
}

}  // namespace quadcosim::analysis
